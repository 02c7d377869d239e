// Test helpers for the decimator: a tiny binary STL loader (tests must not depend on the io
// codecs), a driver that pushes a soup through StreamDecimator in chunks of a given size,
// and topology checks on indexed output and on the half-edge buffer.
#pragma once

#include "decimate/halfedge_buffer.hpp"
#include "decimate/stream_decimator.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace meshstream::decimate::test {

inline std::vector<float> load_binary_stl(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open " + path);
    char header[80];
    uint32_t count = 0;
    in.read(header, 80);
    in.read(reinterpret_cast<char*>(&count), 4);
    std::vector<float> xyz(size_t{9} * count);
    for (uint32_t i = 0; i < count; ++i) {
        char facet[50];
        in.read(facet, 50);
        if (!in) throw std::runtime_error("truncated " + path);
        std::memcpy(&xyz[9 * size_t{i}], facet + 12, 36);
    }
    return xyz;
}

struct Decimated {
    std::vector<float> xyz;     // 9 per triangle
    std::vector<uint64_t> ids;  // 3 per triangle
    Stats stats;
    size_t triangle_count() const { return ids.size() / 3; }
};

inline Decimated run_decimator(const std::vector<float>& soup, const Options& options, size_t chunk_triangles = 4096,
                               bool tell_count = true) {
    const size_t n = soup.size() / 9;
    StreamDecimator decimator(options, tell_count ? std::optional<uint64_t>(n) : std::nullopt);
    Decimated result;
    const Emit emit = [&](const io::TriangleChunk& chunk) {
        result.xyz.insert(result.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        result.ids.insert(result.ids.end(), chunk.vertex_ids().begin(), chunk.vertex_ids().end());
    };
    io::TriangleChunk chunk(chunk_triangles);
    for (size_t i = 0; i < n; ++i) {
        float tri[9];
        std::memcpy(tri, &soup[9 * i], sizeof tri);
        chunk.push(tri);
        if (chunk.full()) {
            decimator.push(chunk, emit);
            chunk.clear();
        }
    }
    if (!chunk.empty()) decimator.push(chunk, emit);
    decimator.finish(emit);
    result.stats = decimator.stats();
    return result;
}

// Indexes a soup by exact position (−0 == +0).
inline std::vector<uint64_t> index_by_position(const std::vector<float>& xyz) {
    std::map<std::array<float, 3>, uint64_t> ids;
    std::vector<uint64_t> out(xyz.size() / 3);
    for (size_t c = 0; c < out.size(); ++c) {
        std::array<float, 3> key{xyz[3 * c] + 0.0f, xyz[3 * c + 1] + 0.0f, xyz[3 * c + 2] + 0.0f};
        out[c] = ids.emplace(key, ids.size()).first->second;
    }
    return out;
}

struct Topology {
    size_t boundary_edges = 0;     // one face
    size_t manifold_edges = 0;     // two faces, opposite directions
    size_t misoriented_edges = 0;  // two faces, same direction
    size_t nonmanifold_edges = 0;  // more than two faces
    size_t degenerate_faces = 0;   // repeated vertex
};

inline Topology topology(const std::vector<uint64_t>& ids) {
    std::unordered_map<uint64_t, std::pair<int, int>> edges;  // key → (a→b count, b→a count)
    Topology t;
    for (size_t f = 0; f < ids.size() / 3; ++f) {
        const uint64_t* v = &ids[3 * f];
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
            ++t.degenerate_faces;
            continue;
        }
        for (int k = 0; k < 3; ++k) {
            uint64_t a = v[k], b = v[(k + 1) % 3];
            const bool forward = a < b;
            if (!forward) std::swap(a, b);
            auto& e = edges[(a << 32) ^ b];
            (forward ? e.first : e.second)++;
        }
    }
    for (const auto& [key, e] : edges) {
        const int total = e.first + e.second;
        if (total == 1)
            ++t.boundary_edges;
        else if (total > 2)
            ++t.nonmanifold_edges;
        else if (e.first == 1)
            ++t.manifold_edges;
        else
            ++t.misoriented_edges;
    }
    return t;
}

inline void triangle_normal(const float* t, double n[3]) {
    const double e1[3] = {t[3] - t[0], t[4] - t[1], t[5] - t[2]};
    const double e2[3] = {t[6] - t[0], t[7] - t[1], t[8] - t[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

// Edges between two faces whose normals are more than ~154° apart (cos < −0.9): knife edges
// and folds. `ids` index the corners of `xyz` (9 floats a triangle).
inline size_t back_to_back_edges(const std::vector<float>& xyz, const std::vector<uint64_t>& ids) {
    std::map<std::pair<uint64_t, uint64_t>, std::vector<size_t>> faces_of_edge;
    for (size_t f = 0; f < ids.size() / 3; ++f)
        for (int k = 0; k < 3; ++k) {
            const uint64_t a = ids[3 * f + k], b = ids[3 * f + (k + 1) % 3];
            faces_of_edge[{std::min(a, b), std::max(a, b)}].push_back(f);
        }
    size_t count = 0;
    for (const auto& [edge, faces] : faces_of_edge) {
        if (faces.size() != 2) continue;
        double m[3], n[3];
        triangle_normal(&xyz[9 * faces[0]], m);
        triangle_normal(&xyz[9 * faces[1]], n);
        const double d = m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
        if (d < 0 &&
            d * d > 0.81 * (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]))
            ++count;
    }
    return count;
}

// Fraction of output area whose normal points against the normal of the nearest input
// triangle (nearest by centroid, through a uniform grid).
inline double flipped_area_fraction(const std::vector<float>& input, const std::vector<float>& output) {
    const size_t n_in = input.size() / 9;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < input.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], input[i]);
        hi[i % 3] = std::max(hi[i % 3], input[i]);
    }
    const int cells = 64;
    auto cell_of = [&](const double c[3], int axis) {
        const double u = (c[axis] - lo[axis]) / (double(hi[axis]) - lo[axis] + 1e-30);
        return std::clamp(int(u * cells), 0, cells - 1);
    };
    std::vector<std::vector<uint32_t>> grid(size_t(cells) * cells * cells);
    auto centroid = [](const float* t, double c[3]) {
        for (int i = 0; i < 3; ++i) c[i] = (double(t[i]) + t[3 + i] + t[6 + i]) / 3;
    };
    for (size_t f = 0; f < n_in; ++f) {
        double c[3];
        centroid(&input[9 * f], c);
        grid[(size_t(cell_of(c, 0)) * cells + cell_of(c, 1)) * cells + cell_of(c, 2)].push_back(uint32_t(f));
    }
    double flipped = 0, total = 0;
    for (size_t f = 0; f < output.size() / 9; ++f) {
        double c[3], n[3];
        centroid(&output[9 * f], c);
        triangle_normal(&output[9 * f], n);
        const double area = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        total += area;
        double best = INFINITY;
        uint32_t nearest = 0;
        const int ci[3] = {cell_of(c, 0), cell_of(c, 1), cell_of(c, 2)};
        for (int r = 1; r <= cells && best == INFINITY; r *= 2) {
            for (int x = std::max(0, ci[0] - r); x <= std::min(cells - 1, ci[0] + r); ++x)
                for (int y = std::max(0, ci[1] - r); y <= std::min(cells - 1, ci[1] + r); ++y)
                    for (int z = std::max(0, ci[2] - r); z <= std::min(cells - 1, ci[2] + r); ++z)
                        for (uint32_t g : grid[(size_t(x) * cells + y) * cells + z]) {
                            double d[3];
                            centroid(&input[9 * size_t{g}], d);
                            const double dist = (d[0] - c[0]) * (d[0] - c[0]) + (d[1] - c[1]) * (d[1] - c[1]) +
                                                (d[2] - c[2]) * (d[2] - c[2]);
                            if (dist < best) {
                                best = dist;
                                nearest = g;
                            }
                        }
        }
        double m[3];
        triangle_normal(&input[9 * size_t{nearest}], m);
        if (n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < 0) flipped += area;
    }
    return total > 0 ? flipped / total : 0;
}

}  // namespace meshstream::decimate::test

namespace meshstream::decimate::test {

// Adds indexed triangles to a buffer; returns the face ids (kNoIndex for degenerate).
inline std::vector<uint32_t> add_indexed(HalfEdgeBuffer& buffer, const std::vector<std::array<float, 3>>& points,
                                         const std::vector<std::array<int, 3>>& faces) {
    std::vector<uint32_t> ids;
    for (const auto& f : faces) {
        float tri[9];
        for (int k = 0; k < 3; ++k)
            for (int i = 0; i < 3; ++i) tri[3 * k + i] = points[f[k]][i];
        ids.push_back(buffer.add_triangle(tri).face);
    }
    return ids;
}

inline const std::vector<std::array<float, 3>>& octahedron_points() {
    static const std::vector<std::array<float, 3>> p = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                                        {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    return p;
}
inline const std::vector<std::array<int, 3>>& octahedron_faces() {
    static const std::vector<std::array<int, 3>> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                                      {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return f;
}

// The buffer vertex at exact position p (linear search over live faces), or kNoIndex.
inline uint32_t vertex_at(const HalfEdgeBuffer& buffer, const std::array<float, 3>& p) {
    for (uint32_t f = 0; f < buffer.face_slots(); ++f)
        for (uint32_t k = 0; buffer.face_alive(f) && k < 3; ++k) {
            const uint32_t v = buffer.corner_vertex(decimate::half_edge(f, k));
            const float* x = buffer.vertex(v).pos;
            if (x[0] == p[0] && x[1] == p[1] && x[2] == p[2]) return v;
        }
    return kNoIndex;
}

// Every half-edge of the in-core faces, in face slot order.
inline std::vector<uint32_t> live_half_edges(const HalfEdgeBuffer& buffer) {
    std::vector<uint32_t> out;
    for (uint32_t f = 0; f < buffer.face_slots(); ++f)
        for (uint32_t k = 0; buffer.face_alive(f) && k < 3; ++k) out.push_back(decimate::half_edge(f, k));
    return out;
}

// The half-edge from vertex a to vertex b, or kNoIndex.
inline uint32_t half_edge(const HalfEdgeBuffer& buffer, uint32_t a, uint32_t b) {
    for (uint32_t c = buffer.vertex(a).first_corner; c != kNoIndex; c = buffer.next_corner(c))
        if (buffer.corner_vertex(next_in_face(c)) == b) return c;
    return kNoIndex;
}

// Structural invariants: twins are mutual and opposite, vertex lists match faces.
inline bool buffer_consistent(const HalfEdgeBuffer& buffer) {
    for (uint32_t f = 0; f < buffer.face_slots(); ++f)
        for (uint32_t k = 0; buffer.face_alive(f) && k < 3; ++k) {
            const uint32_t h = decimate::half_edge(f, k);
            const uint32_t t = buffer.twin(h);
            if (!is_half_edge(t)) continue;
            if (buffer.twin(t) != h) return false;
            if (buffer.corner_vertex(t) != buffer.corner_vertex(next_in_face(h))) return false;
            if (buffer.corner_vertex(next_in_face(t)) != buffer.corner_vertex(h)) return false;
            bool listed = false;
            const uint32_t v = buffer.corner_vertex(h);
            for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) listed |= c == h;
            if (!listed) return false;
        }
    return true;
}

}  // namespace meshstream::decimate::test
