// PLY (Stanford polygon file format), ascii, binary_little_endian and binary_big_endian.
// Memory class: O(vertices), spilled past --memory. The reader keeps the vertex table
// (io/vertex_table.hpp: in memory within the budget, else a temp file or the input's own
// vertex block read in place) and streams the faces, triangulating polygons
// (io/triangulate.hpp: the fan from the first corner when convex, else ear clipping). The
// writer welds (io/weld.hpp) and assembles header, vertices and faces at finish(), so the
// output is valid even on stdout.
//
// Reader: x, y, z of any numeric type; red/green/blue fill the colour channel; every other
// property and element (before the vertices, between, after the faces; scalars or lists) is
// skipped; faces are the list `vertex_indices` or `vertex_index` with any count and index
// types. Corners carry the file's vertex index in the vertex_id channel. `comment meshstream
// sorted-axis=x|y|z` sets MeshHeader::sorted_axis. triangle_count is left unknown when there
// are faces (polygons are known only while reading; no pre-pass).
// Writer: float x, y, z (+ uchar red, green, blue when the input has colour), faces as
// `list uchar int vertex_indices`; "ply" writes binary little endian, "ply-ascii" ascii with
// shortest round-trip floats.
#pragma once

#include "io/format.hpp"

namespace meshstream::io {

extern const Format kPlyFormat;       // "ply": reads every encoding, writes binary LE
extern const Format kPlyAsciiFormat;  // "ply-ascii": writes ascii (reads like "ply")

// True when `head` starts with the PLY magic line ("ply" + LF or CRLF).
bool probe_ply(std::span<const std::byte> head, std::optional<uint64_t> file_size);

}  // namespace meshstream::io
