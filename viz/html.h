#pragma once
// HTML pages fleetmap writes: each one self-contained (its script, styles and data inside), so it
// opens from disk in any browser without a network.
#include <string>
#include <string_view>

namespace fleetmap::viz {

// Text safe inside HTML elements and quoted attributes.
std::string html_escape(std::string_view text);

// The replay page (replay.h) around its JSON data, which must hold no '<'.
std::string replay_page(const std::string& title, const std::string& json);

// Every page's start: doctype, charset, viewport, generator, up to an open <title>.
std::string_view page_head();

// The page's shared look: a <style> element for tables, plots and tooltips.
std::string_view page_style();

}  // namespace fleetmap::viz
