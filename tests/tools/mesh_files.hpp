// Meshes the CLI tests write and check: a generated height-field grid, its binary STL, a
// meshstream-gen mesh, and what a written file holds (triangle count, edge counts).
#pragma once

#include "compare/topology.hpp"
#include "io/format.hpp"
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace cli_test {

// A height-field grid of 2·k² triangles in row order (a stream the decimator can work on), 9
// floats each.
inline std::vector<float> grid(int k) {
    std::vector<float> tris;
    tris.reserve(size_t(18) * size_t(k) * size_t(k));
    auto z = [](int x, int y) { return 0.01f * float((x * 7 + y * 13) % 11); };
    for (int y = 0; y < k; ++y)
        for (int x = 0; x < k; ++x) {
            const float x0 = float(x), x1 = float(x + 1), y0 = float(y), y1 = float(y + 1);
            tris.insert(tris.end(), {x0, y0, z(x, y), x1, y0, z(x + 1, y), x1, y1, z(x + 1, y + 1)});
            tris.insert(tris.end(), {x0, y0, z(x, y), x1, y1, z(x + 1, y + 1), x0, y1, z(x, y + 1)});
        }
    return tris;
}

// A binary STL of `tris` (9 floats each), zero normals.
inline std::string binary_stl(const std::vector<float>& tris) {
    std::string s(80, ' ');
    const uint32_t n = static_cast<uint32_t>(tris.size() / 9);
    s.append(reinterpret_cast<const char*>(&n), 4);
    for (size_t t = 0; t < n; ++t) {
        s.append(12, '\0');
        s.append(reinterpret_cast<const char*>(&tris[9 * t]), 36);
        s.append(2, '\0');
    }
    return s;
}

// The edge counts (boundary, non-manifold) of the mesh in `path`.
inline meshstream::compare::EdgeCounts edges_of(const std::string& path) {
    namespace io = meshstream::io;
    io::Input in = io::open_input(path);
    io::TriangleChunk chunk;
    meshstream::compare::EdgeCounter counter;
    while (in.reader->next(chunk))
        for (size_t t = 0; t < chunk.size(); ++t) counter.add_triangle(&chunk.xyz()[9 * t]);
    return counter.finish();
}

// The triangle count `path`'s header states.
inline uint64_t triangles_of(const std::string& path) {
    return *meshstream::io::open_input(path).reader->triangle_count();
}

#ifdef MESHSTREAM_GEN_BINARY
// A closed marching-cubes mesh of about `triangles` triangles (meshstream-gen, binary STL), made
// once per size for the test program; the path stays valid to its end.
inline const std::string& generated_mesh(uint64_t triangles) {
    static TempDir dir;
    static std::map<uint64_t, std::string> made;
    if (const auto it = made.find(triangles); it != made.end()) return it->second;
    const std::string path = dir / ("generated_" + std::to_string(triangles) + ".stl");
    const std::string cmd = std::string(MESHSTREAM_GEN_BINARY) + " -q -n " + std::to_string(triangles) + " " + path;
    if (std::system(cmd.c_str()) != 0) ADD_FAILURE() << cmd;
    return made.emplace(triangles, path).first->second;
}
#endif

// `mesh` converted (meshstream convert) to a binary little-endian PLY at `path`, with one vertex
// index of face `faces · fraction` set out of range (0x7fffffff): bad input at a known place.
// The file's bytes and that face's index.
struct BadPly {
    std::string bytes;
    uint64_t bad_face = 0;
};
inline BadPly write_ply_with_bad_index(const std::string& mesh, const std::string& path, double fraction) {
    if (run("convert -q " + mesh + " " + path).code != 0) ADD_FAILURE() << "convert " << mesh;
    BadPly ply{slurp(path), 0};
    const size_t body = ply.bytes.find("end_header\n") + 11;
    const uint64_t vertices = std::stoull(ply.bytes.substr(ply.bytes.find("element vertex ") + 15));
    const uint64_t faces = std::stoull(ply.bytes.substr(ply.bytes.find("element face ") + 13));
    ply.bad_face = uint64_t(double(faces) * fraction);
    const uint32_t index = 0x7fffffff;
    std::memcpy(&ply.bytes[body + 12 * vertices + 13 * ply.bad_face + 1], &index, 4);  // uchar count, int indices
    std::ofstream(path, std::ios::binary | std::ios::trunc) << ply.bytes;
    return ply;
}

}  // namespace cli_test
