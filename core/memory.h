#pragma once
// How a program's C library hands freed memory back: a setting for programs that merge, prepare or
// step large maps over and over.
#include <cstddef>

namespace fleetmap::core {

// A merge of two 1000 x 1000 maps allocates and frees some tens of MB of images. By default glibc
// serves blocks of a few MB with fresh pages and hands freed ones back to the system, so every merge
// faults its pages in again (measured: 2200-4000 page faults per merge in a loop of merges, a fifth
// to two fifths of its time on a virtual machine where a fault costs several microseconds).
// This asks the C library to serve blocks below `heap_block_bytes` from its heap and to keep up to
// `retain_bytes` of freed heap for reuse (glibc's M_MMAP_THRESHOLD and M_TRIM_THRESHOLD; the
// memory kept is mostly reused: measured, a Python loop's peak unchanged, an exploration's 14 MB
// higher, bench/README.md "Freed memory kept for reuse"). Process-wide, so the application's choice:
// call it once, early, from a program's main (the `fleetmap` program does; from Python,
// fleetmap.keep_freed_memory()); linking or importing fleetmap never does. Returns false
// where the C library has no such settings (not glibc, or an allocator a sanitizer replaced).
bool keep_freed_memory(std::size_t heap_block_bytes = std::size_t(32) << 20,
                       std::size_t retain_bytes = std::size_t(128) << 20);

}  // namespace fleetmap::core
