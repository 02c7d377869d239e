// STL, binary and ASCII. Memory class: streams (one chunk plus a 1 MiB read buffer).
// Binary: 80-byte header, uint32 count, 50-byte facets (normal, 3 vertices, attribute u16).
// ASCII: "solid name / facet normal / outer loop / vertex ×3 / endloop / endfacet / endsolid".
#pragma once

#include "io/format.hpp"

namespace meshstream::io {

extern const Format kStlFormat;       // "stl": binary STL (reads binary and ASCII)
extern const Format kStlAsciiFormat;  // "stl-ascii": ASCII STL

// True when a file of `size` bytes starting with `head` is binary STL: 84 + 50·n == size,
// or (size unknown) the head does not look like ASCII "solid".
bool probe_stl_binary(std::span<const std::byte> head, std::optional<uint64_t> size);

}  // namespace meshstream::io
