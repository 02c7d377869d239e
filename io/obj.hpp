// Wavefront OBJ, geometry only. Memory class: O(vertices), spilled past --memory (the reader's
// vertex table, io/vertex_table.hpp; the writer's welding, io/weld.hpp).
//
// Reader: `v x y z` (extra w or colour values ignored), `f` in every form (`1`, `1/2`, `1//3`,
// `1/2/3`) with negative (relative) indices, a `#` comment ending either line, polygons triangulated (io/triangulate.hpp: the
// fan from the first corner when convex, else ear clipping; n - 2 triangles), `\` line
// continuations, comments, CRLF; every other statement (vt vn g o s usemtl mtllib l p ...) is
// skipped. A face may only use vertices defined before it (the OBJ rule), so one pass works.
// Corners carry the 0-based OBJ vertex number in the vertex_id channel. `# meshstream
// sorted-axis=x|y|z` sets MeshHeader::sorted_axis.
// Writer: a comment, `v` lines, then `f` lines (1-based, triangles), welded; floats in the
// shortest form that round-trips.
#pragma once

#include "io/format.hpp"

namespace meshstream::io {

extern const Format kObjFormat;  // "obj"

// OBJ has no magic: true when the head is text whose first statement is an OBJ keyword
// (v, vt, vn, f, o, g, s, usemtl, mtllib, l, p) or which holds only '#' comments. So weak a
// test ("g" is the first byte of a GLB, "p" of a PLY) is kObjFormat's guess, tried only when
// neither magic bytes nor the extension identify the input.
bool guess_obj(std::span<const std::byte> head);

}  // namespace meshstream::io
