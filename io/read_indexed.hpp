// A whole mesh file as one indexed mesh in memory (vertices, indices and channels), for library
// users who want arrays rather than the chunk stream, as miniply and tinyobjloader give. The
// file is opened through the same registry and detection as the commands. A file whose corners
// are its vertices, attributes and all (PLY: Reader::indexed), keeps its own: its vertices in
// file order, those no triangle uses left out, and its faces' indices. Any other is read as the
// commands read it and welded as the whole-mesh writers weld (io::MeshIndexer): corners with
// bit-equal positions (or, from readers that index, the same vertex id) and equal attributes
// are one vertex, numbered in the order the triangles first use them, so UV and normal seams
// (an OBJ's) stay apart. Every triangle is kept in file order, degenerate ones too, except those
// with a NaN or infinite coordinate, which are dropped and counted (an io::Error under
// ReadOptions::strict); NaN or infinite attribute values are stored as 0 and counted (per
// vertex from a file that keeps its own, per corner otherwise).
// Memory: the whole mesh (see io::IndexedMesh), plus the reader's own buffers while reading
// (and 1 byte a file vertex for a file that keeps its own).
#pragma once

#include "io/format.hpp"
#include "io/mesh_index.hpp"

#include <cstdint>
#include <string>
#include <string_view>

namespace meshstream::io {

struct IndexedFile {
    IndexedMesh mesh;  // channels: the per-vertex ones of ReadOptions::channels, and the material
    // The file's header once read to the end: its material table (which mesh.materials
    // indexes), variant, notes and the reader's counted warnings.
    MeshHeader header;
    const Format* format = nullptr;      // the format the file was read as
    uint64_t non_finite_triangles = 0;   // dropped for a NaN or infinite coordinate
    uint64_t non_finite_attributes = 0;  // normal, colour, uv or scalar values that were NaN or infinite: 0 in the mesh
};

// Reads `path` ("-": standard input) as format `from` (empty: detected, as the commands do).
// Throws io::Error naming the file and position for what the reader rejects, for a header
// whose triangle count the data does not match, and for an index count past 2^32 - 1.
IndexedFile read_indexed(const std::string& path, const ReadOptions& options = {}, std::string_view from = {});

}  // namespace meshstream::io
