// Helpers shared by the Draco and glTF tests: temp dirs, reading/writing whole soups through
// the registry, running the real clients (draco_decoder, the Khronos glTF validator), and the
// quantization-bound matcher for lossy round trips.
#pragma once

#include "test_util.hpp"

#include "io/error.hpp"
#include "io/format.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace web_test {

namespace io = meshstream::io;
namespace fs = std::filesystem;
using meshstream::test::slurp;
using meshstream::test::TempDir;

inline std::string fixture(const std::string& name) { return std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name; }

// A fresh directory per test, removed afterwards.
struct Soup {
    std::vector<float> xyz;  // 9 per triangle
    size_t triangles() const { return xyz.size() / 9; }
};

inline Soup read_soup(const std::string& path, size_t capacity = io::TriangleChunk::kDefaultCapacity,
                      io::MeshHeader* header = nullptr, const io::ReadOptions& options = {}) {
    io::Input in = io::open_input(path, {}, options);
    if (header) *header = in.reader->header();
    io::TriangleChunk chunk(capacity);
    Soup s;
    while (in.reader->next(chunk)) s.xyz.insert(s.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
    return s;
}

// The writer's notes in the library's words (io::render).
inline std::vector<std::string> notes_in_words(const io::Writer& writer) {
    std::vector<std::string> out;
    for (const std::string& note : writer.notes()) out.push_back(io::render(note));
    return out;
}

// Writes `soup` to `path`; returns the writer's notes in the library's words.
inline std::vector<std::string> write_soup(const Soup& soup, const std::string& path,
                                           const io::WriteOptions& options = {}) {
    io::Output out = io::open_output(path, {}, options);
    io::TriangleChunk chunk(1000);
    for (size_t t = 0; t < soup.triangles(); ++t) {
        if (chunk.full()) {
            out.write(chunk);
            chunk.clear();
        }
        float tri[9];
        std::copy(&soup.xyz[9 * t], &soup.xyz[9 * t] + 9, tri);
        chunk.push(tri);
    }
    if (!chunk.empty()) out.write(chunk);
    out.finish();
    return notes_in_words(*out.writer);
}

// A soup with every channel its reader fills (the header's), corner by corner.
struct Mesh {
    io::MeshHeader header;                     // as it stands after the last chunk
    std::vector<float> xyz, normals, colors;   // per corner: 3, 3, 4 (RGBA)
    std::vector<float> uvs;                    // per corner: 2 (set 0)
    std::vector<uint32_t> materials;           // per triangle
    std::vector<std::vector<double>> scalars;  // per vertex scalar channel, per corner
    std::vector<uint64_t> ids;                 // per corner
    size_t triangles() const { return xyz.size() / 9; }
};

inline Mesh read_mesh(const std::string& path) {
    io::Input in = io::open_input(path);
    Mesh m;
    const io::Channels ch = in.reader->header().channels;
    m.scalars.resize(ch.vertex_scalars.size());
    io::TriangleChunk chunk(1000, ch);
    while (in.reader->next(chunk)) {
        for (size_t i = 0; i < chunk.size(); ++i) {
            m.xyz.insert(m.xyz.end(), &chunk.xyz()[9 * i], &chunk.xyz()[9 * i] + 9);
            if (ch.normal) m.normals.insert(m.normals.end(), chunk.normal_at(i), chunk.normal_at(i) + 9);
            if (ch.color) m.colors.insert(m.colors.end(), chunk.color_at(i), chunk.color_at(i) + 12);
            if (ch.uv_sets > 0) m.uvs.insert(m.uvs.end(), chunk.uv_at(i, 0), chunk.uv_at(i, 0) + 6);
            if (ch.material) m.materials.push_back(*chunk.material_at(i));
            if (ch.vertex_id) m.ids.insert(m.ids.end(), chunk.id_at(i), chunk.id_at(i) + 3);
            for (size_t c = 0; c < ch.vertex_scalars.size(); ++c)
                m.scalars[c].insert(m.scalars[c].end(), chunk.vertex_scalar_at(i, c), chunk.vertex_scalar_at(i, c) + 3);
        }
    }
    m.header = in.reader->header();
    return m;
}

// Writes `m` to `path` with the channels the output format keeps of m's (and its materials),
// the way convert does; returns the writer's notes in the library's words.
inline std::vector<std::string> write_mesh(const Mesh& m, const std::string& path, io::WriteOptions options = {}) {
    const io::Format& format = io::output_format(path, {});
    const io::Channels& in = m.header.channels;
    options.channels = io::writable_channels(format, in, options);
    options.materials = m.header.materials;
    const io::Channels& ch = options.channels;
    io::Output out = io::open_output(path, {}, options);
    io::TriangleChunk chunk(1000, ch);
    for (size_t t = 0; t < m.triangles(); ++t) {
        if (chunk.full()) {
            out.write(chunk);
            chunk.clear();
        }
        float* p = chunk.push_slot();
        const size_t i = chunk.size() - 1;
        std::copy(&m.xyz[9 * t], &m.xyz[9 * t] + 9, p);
        if (ch.normal) std::copy(&m.normals[9 * t], &m.normals[9 * t] + 9, chunk.normal_at(i));
        if (ch.color) std::copy(&m.colors[12 * t], &m.colors[12 * t] + 12, chunk.color_at(i));
        if (ch.uv_sets > 0) std::copy(&m.uvs[6 * t], &m.uvs[6 * t] + 6, chunk.uv_at(i, 0));
        if (ch.material) *chunk.material_at(i) = m.materials[t];
        if (ch.vertex_id) std::copy(&m.ids[3 * t], &m.ids[3 * t] + 3, chunk.id_at(i));
        for (size_t c = 0; c < ch.vertex_scalars.size(); ++c)
            for (size_t s = 0; s < in.vertex_scalars.size(); ++s)
                if (in.vertex_scalars[s].name == ch.vertex_scalars[c].name)
                    std::copy(&m.scalars[s][3 * t], &m.scalars[s][3 * t] + 3, chunk.vertex_scalar_at(i, c));
    }
    if (!chunk.empty()) out.write(chunk);
    out.finish();
    return notes_in_words(*out.writer);
}

// The largest differences between the channels of two meshes holding the same triangles in
// any order, any starting corner: each triangle of `a` is matched to the one of `b` whose
// corners lie within `position_tolerance` (max norm), corner to corner.
struct ChannelErrors {
    size_t unmatched = 0;
    double position = 0, normal = 0, color = 0, uv = 0, scalar = 0;
    size_t material_mismatches = 0;
};
inline ChannelErrors compare_meshes(const Mesh& a, const Mesh& b, double position_tolerance) {
    ChannelErrors e;
    if (a.triangles() != b.triangles()) {
        e.unmatched = a.triangles();
        return e;
    }
    // Grid of b's triangles by centroid, cells of 4 tolerances (and at least 1e-6).
    const double cell = std::max(4 * position_tolerance, 1e-6);
    auto key = [&](const float* t, int dx, int dy, int dz) {
        const long x = std::lround((t[0] + t[3] + t[6]) / 3 / cell) + dx,
                   y = std::lround((t[1] + t[4] + t[7]) / 3 / cell) + dy,
                   z = std::lround((t[2] + t[5] + t[8]) / 3 / cell) + dz;
        return std::array<long, 3>{x, y, z};
    };
    std::multimap<std::array<long, 3>, size_t> grid;
    for (size_t t = 0; t < b.triangles(); ++t) grid.emplace(key(&b.xyz[9 * t], 0, 0, 0), t);
    std::vector<bool> used(b.triangles(), false);
    for (size_t t = 0; t < a.triangles(); ++t) {
        const float* pa = &a.xyz[9 * t];
        size_t best = SIZE_MAX;
        int best_rot = 0;
        double best_err = 1e300;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    auto [lo, hi] = grid.equal_range(key(pa, dx, dy, dz));
                    for (auto it = lo; it != hi; ++it) {
                        if (used[it->second]) continue;
                        const float* pb = &b.xyz[9 * it->second];
                        for (int r = 0; r < 3; ++r) {
                            double err = 0;
                            for (int k = 0; k < 3; ++k)
                                for (int c = 0; c < 3; ++c)
                                    err = std::max(err, std::abs(double(pa[3 * k + c]) - pb[3 * ((k + r) % 3) + c]));
                            if (err < best_err) best_err = err, best = it->second, best_rot = r;
                        }
                    }
                }
        if (best == SIZE_MAX || best_err > position_tolerance) {
            ++e.unmatched;
            continue;
        }
        used[best] = true;
        e.position = std::max(e.position, best_err);
        for (int k = 0; k < 3; ++k) {
            const size_t ca = 3 * t + k, cb = 3 * best + (k + best_rot) % 3;
            if (!a.normals.empty() && !b.normals.empty())
                for (int c = 0; c < 3; ++c)
                    e.normal = std::max(e.normal, std::abs(double(a.normals[3 * ca + c]) - b.normals[3 * cb + c]));
            if (!a.colors.empty() && !b.colors.empty())
                for (int c = 0; c < 4; ++c)
                    e.color = std::max(e.color, std::abs(double(a.colors[4 * ca + c]) - b.colors[4 * cb + c]));
            if (!a.uvs.empty() && !b.uvs.empty())
                for (int c = 0; c < 2; ++c)
                    e.uv = std::max(e.uv, std::abs(double(a.uvs[2 * ca + c]) - b.uvs[2 * cb + c]));
            for (size_t s = 0; s < a.scalars.size() && s < b.scalars.size(); ++s)
                e.scalar = std::max(e.scalar, std::abs(a.scalars[s][ca] - b.scalars[s][cb]));
        }
        if (!a.materials.empty() && !b.materials.empty())
            e.material_mismatches +=
                a.header.materials[a.materials[t]].name != b.header.materials[b.materials[best]].name;
    }
    return e;
}

// Runs a shell command; returns its exit status and captures stdout into `out`.
inline int run(const std::string& command, std::string* out = nullptr) {
    FILE* p = ::popen(command.c_str(), "r");
    if (!p) return -1;
    std::string text;
    char buf[4096];
    while (size_t n = std::fread(buf, 1, sizeof buf, p)) text.append(buf, n);
    int status = ::pclose(p);
    if (out) *out = std::move(text);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string quote(const std::string& s) { return "'" + s + "'"; }

// Bit-for-bit Draco position quantization (draco::Quantizer, AttributeQuantizationTransform:
// range = largest bbox extent, q = floor((v - min) · (2^bits - 1) / range + 0.5) in float).
struct Quantization {
    float min[3];
    float range;
    int bits;
    Quantization(const Soup& s, int qp) : bits(qp) {
        float max[3];
        for (int a = 0; a < 3; ++a) min[a] = max[a] = s.xyz[a];
        for (size_t i = 0; i < s.xyz.size(); i += 3)
            for (int a = 0; a < 3; ++a) {
                min[a] = std::min(min[a], s.xyz[i + a]);
                max[a] = std::max(max[a], s.xyz[i + a]);
            }
        range = 0;
        for (int a = 0; a < 3; ++a) range = std::max(range, max[a] - min[a]);
        if (range == 0) range = 1;
    }
    float max_q() const { return static_cast<float>((1 << bits) - 1); }
    // The bound the issue asks for: half a quantization step, step = bbox range / (2^qp - 1).
    double bound() const { return 0.5 * double(range) / max_q(); }
    int32_t quantize(float v, int a) const {
        float inverse_delta = max_q() / range;
        float val = (v - min[a]) * inverse_delta;
        return static_cast<int32_t>(std::floor(val + 0.5f));
    }
    // Grid index of a decoded (already dequantized) coordinate.
    int32_t snap(float v, int a) const {
        return static_cast<int32_t>(std::lround((double(v) - min[a]) / (double(range) / max_q())));
    }
};

using TriKey = std::array<int32_t, 9>;

// Canonical rotation (smallest corner first) keeps orientation but forgets the start corner.
inline TriKey canonical(TriKey k) {
    int best = 0;
    for (int c = 1; c < 3; ++c)
        if (std::lexicographical_compare(&k[3 * c], &k[3 * c] + 3, &k[3 * best], &k[3 * best] + 3)) best = c;
    TriKey out;
    for (int c = 0; c < 3; ++c)
        for (int a = 0; a < 3; ++a) out[3 * c + a] = k[3 * ((best + c) % 3) + a];
    return out;
}

// Asserts that `decoded` is `original` after Draco quantization with `qp` bits: the same
// number of triangles, each original triangle matched (same orientation, any order or start
// corner) by a decoded one whose corners lie within the half-step bound of the originals.
// Returns the largest coordinate error found (0 when the input already sat on the grid, as
// the bunny does at 14 bits: it was decoded from a 14-bit Draco file).
inline double expect_within_quantization_bound(const Soup& original, const Soup& decoded, int qp) {
    EXPECT_EQ(decoded.triangles(), original.triangles());
    if (decoded.triangles() != original.triangles()) return -1;
    Quantization q(original, qp);
    const double bound = q.bound() * (1 + 1e-5) + 1e-7 * q.range;  // float rounding of min + q·delta
    std::multimap<TriKey, size_t> by_key;
    for (size_t t = 0; t < decoded.triangles(); ++t) {
        TriKey k;
        for (int i = 0; i < 9; ++i) k[i] = q.snap(decoded.xyz[9 * t + i], i % 3);
        by_key.emplace(canonical(k), t);
    }
    double worst = 0;
    size_t unmatched = 0;
    for (size_t t = 0; t < original.triangles(); ++t) {
        TriKey k;
        for (int i = 0; i < 9; ++i) k[i] = q.quantize(original.xyz[9 * t + i], i % 3);
        auto it = by_key.find(canonical(k));
        if (it == by_key.end()) {
            ++unmatched;
            continue;
        }
        // Compare as point sets of the two triangles: every original corner has a decoded
        // corner within the bound.
        const float* d = &decoded.xyz[9 * it->second];
        for (int c = 0; c < 3; ++c) {
            double best = 1e300;
            for (int e = 0; e < 3; ++e) {
                double m = 0;
                for (int a = 0; a < 3; ++a)
                    m = std::max(m, std::abs(double(original.xyz[9 * t + 3 * c + a]) - d[3 * e + a]));
                best = std::min(best, m);
            }
            worst = std::max(worst, best);
        }
        by_key.erase(it);
    }
    EXPECT_EQ(unmatched, 0u) << "original triangles without a quantized counterpart";
    EXPECT_LE(worst, bound) << "largest coordinate error " << worst << " vs bound " << q.bound();
    return worst;
}

}  // namespace web_test
