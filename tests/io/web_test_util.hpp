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

// Writes `soup` to `path`; returns the writer's notes.
inline std::vector<std::string> write_soup(const Soup& soup, const std::string& path, const io::WriteOptions& options = {}) {
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
    return out.writer->notes();
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
    int32_t snap(float v, int a) const { return static_cast<int32_t>(std::lround((double(v) - min[a]) / (double(range) / max_q()))); }
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
                for (int a = 0; a < 3; ++a) m = std::max(m, std::abs(double(original.xyz[9 * t + 3 * c + a]) - d[3 * e + a]));
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
