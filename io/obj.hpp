// Wavefront OBJ with its MTL material library (io/mtl.hpp). Memory class: O(vertices),
// spilled past --memory (the reader's tables, io/vertex_table.hpp; the writer's welding,
// io/weld.hpp); texture images are held whole, at most --memory of them.
//
// Reader: `v x y z` (then w, r g b, or w r g b: colours as float RGB, values as written),
// `vt u [v [w]]` (u, v kept), `vn x y z`, `f` in every form (`1`, `1/2`, `1//3`, `1/2/3`,
// and `fo`) with negative (relative) indices, each checked against the elements defined before
// the face (the OBJ rule, so one pass works); polygons triangulated (io/triangulate.hpp: the
// fan from the first corner when convex, else ear clipping; n - 2 triangles); `\` line
// continuations, `#` comments (also ending v/vt/vn/f lines), CRLF, a UTF-8 byte order mark.
// Channels are decided once, for the whole stream, by what comes first, since a reader states
// them before its first chunk: everything up to the first face is read when the reader opens.
//  - colour when the first `v` has one; later vertices without one are white, counted;
//  - texture coordinates (uv set 0) / normals when the first face's corners use vt / vn; later
//    corners without them get (0, 0) / (0, 0, 0), counted; a face using them when the first
//    face did not has them dropped, counted;
//  - materials when `mtllib` or `usemtl` comes before the first face: `usemtl` gives each
//    triangle the index of its name in MeshHeader::materials, which holds the MTL files'
//    materials (mtllib names them relative to the OBJ's directory, the current directory on
//    stdin), then names used but defined nowhere (white, kept by name; one warning; a missing
//    MTL file is one warning too). Faces before the first usemtl (a file that names its
//    library first) get a material "default" (white), added only then (also when no usemtl
//    follows at all: that cannot be known at the first face), and so do faces after a usemtl
//    without a name (counted in MeshHeader::warnings; an error under ReadOptions::strict).
//    A usemtl name first met after the first face is appended to the table while reading (see
//    Writer::update_materials). With neither before the first face, later ones are dropped,
//    counted. The MTL files and images read are listed in MeshHeader::side_files.
// Vertex ids: with texture coordinates or normals in the chunk, one id per distinct
// (v, vt, vn) triple in use, so seams are different vertices (ids in order of first use,
// from a table of 40 bytes a triple within its share of the budget; a triple not met again
// before that table is full and it is the least recently used of its set gets a second id
// if it comes back: its vertex is then written twice); otherwise the 0-based OBJ vertex
// number. `# meshstream sorted-axis=x|y|z` sets MeshHeader::sorted_axis.
// Memory: positions (12 bytes each, 24 with colour), texture coordinates (12) and normals
// (12) are three io::VertexTables and the corner ids a fourth table, sharing --memory in the
// ratio 2 : 1 : 1 : 1 among those present; each spills past its share.
// Skipped, with one counted note each (MeshHeader::notes, "warning"): faces with fewer than 3
// corners (an error with --strict), `l` and `p`, free-form geometry (vp, curv, surf, ...) and
// unknown statements; g, o, s, mg and display attributes are skipped without a word.
//
// Writer: a comment, `mtllib` when there are materials, one `v` (with `r g b` when coloured),
// `vt` and `vn` per welded vertex (welded on position and attributes, so seams stay apart),
// then `f` lines (1-based, triangles, `i/i/i` forms) in input order with a `usemtl` where the
// material changes; floats in the shortest form that round-trips. Keeps normals, RGB colour
// (alpha is dropped), uv set 0 and materials. Materials go to `<stem>.mtl` beside the output
// (Kd, d, map_Kd) and their images beside it under their own file names made safe (bytes
// other than letters, digits, . - _ become _); an image file already there with the same
// bytes is used as it is, any other file gives a numbered name (tex_2.png): nothing is
// overwritten. An existing `<stem>.mtl` is replaced only when an existing OBJ of the output's
// name uses it, else refused before any work; Format::side_files names it, so the commands
// also refuse it when it is a file an input's reader read. All side files are written to temporary names
// and renamed only once every one of them and the OBJ are complete. On stdout, a pipe or a
// device there are no side files: `usemtl` names only, and a note saying so.
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
