// PLY (Stanford polygon file format), ascii, binary_little_endian and binary_big_endian.
// Memory class: O(vertices), spilled past --memory. The reader keeps the vertex table
// (io/vertex_table.hpp: in memory within the budget, else a temp file or the input's own
// vertex block read in place) and streams the faces, triangulating polygons
// (io/triangulate.hpp: the fan from the first corner when convex, else ear clipping). The
// writer welds (io/weld.hpp) and assembles header, vertices and faces at finish(), so the
// output is valid even on stdout; face scalars wait in a temporary file meanwhile.
//
// Reader: x, y, z of any numeric type; nx, ny, nz (or normal_x, ...) the normal; red, green,
// blue (+ alpha) of one type, uchar, ushort, float or double, the colour; uv set 0 from
// texture_u/texture_v, else texture_s/texture_t, u/v or s/t (float or double), sets 1-3 from
// texture_u1/texture_v1, ...; every other vertex scalar a named vertex scalar, and every face
// scalar but the index list a named face scalar (per-face colours too), in the file's type.
// Only the channels the caller asks for (ReadOptions::channels) are stored: a binary file in
// host byte order with float positions is then read in place whatever else its vertices hold.
// List properties other than the face indices and elements other than vertex and face are not
// read: each is one counted warning (MeshHeader::warnings). Faces are the list `vertex_indices`
// or `vertex_index` with any count and index types; faces of fewer than 3 vertices are skipped
// with a counted warning (an error under --strict). Corners carry the file's vertex index in
// the vertex_id channel. `comment meshstream sorted-axis=x|y|z` sets MeshHeader::sorted_axis.
// triangle_count is left unknown when there are faces (polygons are known only while reading;
// no pre-pass). Header lines that are no keyword are skipped like comments with a counted
// warning (an error under --strict). Counts that disagree with the data are errors: ascii
// items must start on a line of their own, and a binary file's bytes must all be accounted for.
// Writer: float x, y, z and every channel but materials (PLY has no material table): float
// nx, ny, nz; red, green, blue (+ alpha) in the colour's type; float texture_u, texture_v
// (texture_u1, ... for further sets); vertex scalars in their types; faces as `list uchar int
// vertex_indices` with the face scalars after it. "ply" writes binary little endian,
// "ply-ascii" ascii with shortest round-trip floats.
#pragma once

#include "io/format.hpp"

namespace meshstream::io {

extern const Format kPlyFormat;       // "ply": reads every encoding, writes binary LE
extern const Format kPlyAsciiFormat;  // "ply-ascii": writes ascii (reads like "ply")

// True when `head` starts with the PLY magic line ("ply" + LF or CRLF).
bool probe_ply(std::span<const std::byte> head, std::optional<uint64_t> file_size);

}  // namespace meshstream::io
