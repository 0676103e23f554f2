#pragma once
// Notes on how a user's map file was read, printed once to stderr: the defaults it took silently
// (a bare image's resolution) and pixels read in a way that may surprise (io::map_reading_notes).
#include <string>

#include "io/map_io.h"

namespace fleetmap::cli {

// "fleetmap: note: <map>: ..." lines on stderr for a map file; nothing for a built-in map.
void print_map_notes(const std::string& source, const io::MapLoadOptions& options, bool resolution_given,
                     const std::string& resolution_source = "the default; --resolution sets it");

// The same notes for the end of an error message about the map (" (note; note)"), or "".
std::string map_notes_suffix(const std::string& source, const io::MapLoadOptions& options, bool resolution_given);

}  // namespace fleetmap::cli
