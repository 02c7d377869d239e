// libFuzzer target: StreamDecimator push/finish on arbitrary triangle soups. The bytes encode
// options and an indexed soup, so that shared (repeated) vertices are common and the raw
// float bits give NaN, ±inf, denormals, huge and tiny magnitudes:
//   byte 0: buffer_triangles = 16 + 4·b     byte 1: ratio = (b + 1) / 256
//   byte 2: seed = b                        byte 3: weld_eps from a table (0, tiny, 1e-3, 1, huge, inf)
//   byte 4: sorted axis (none, x, y, z)     byte 5: bit 0 = use --target (target = byte 1, ≥ 1)
//                                                   bits 1..: input chunk capacity 1 + (b >> 1)
//   byte 6: palette size P = 1 + b % 64, then P × 12 bytes of float xyz,
//   then triangles as 3 palette index bytes each (mod P).
// Triangles with a NaN/inf corner are dropped before push(), as io::TriangleInput does in
// the commands: finite coordinates are push()'s asserted precondition (the first fuzz run
// found the decimator's finish() asserting on them). Huge, tiny, denormal and repeated
// coordinates all go in. Checked: asserts and sanitizers inside, the emitted count equals
// stats().triangles_out, and no NaN comes out of finite input.
#include "decimate/stream_decimator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace meshstream;
    if (size < 7) return 0;
    decimate::Options options;
    options.buffer_triangles = 16 + 4 * size_t{data[0]};
    options.ratio = (data[1] + 1) / 256.0;
    options.seed = data[2];
    constexpr double kEps[] = {0, 1e-30, 1e-3, 1, 1e30, std::numeric_limits<double>::infinity()};
    options.weld_eps = kEps[data[3] % 6];
    if (data[4] % 4) options.sorted_axis = data[4] % 4 - 1;
    options.output_chunk_triangles = 1 + data[5] % 5;
    const bool use_target = data[5] & 1;
    const size_t in_capacity = 1 + (data[5] >> 1);
    const size_t palette = 1 + data[6] % 64;
    size_t pos = 7;
    if (size < pos + 12 * palette) return 0;
    std::vector<float> xyz(3 * palette);
    std::memcpy(xyz.data(), data + pos, 12 * palette);
    pos += 12 * palette;
    const uint64_t triangles = (size - pos) / 3;

    if (use_target) options.target = std::clamp<uint64_t>(data[1], 1, std::max<uint64_t>(triangles, 1));
    decimate::StreamDecimator decimator(options, triangles);
    uint64_t out_count = 0;
    auto emit = [&](const io::TriangleChunk& chunk) {
        out_count += chunk.size();
        for (float v : chunk.xyz())
            if (std::isnan(v)) __builtin_trap();
    };
    io::TriangleChunk chunk(in_capacity);
    for (uint64_t t = 0; t < triangles; ++t) {
        float tri[9];
        for (int c = 0; c < 3; ++c) std::memcpy(&tri[3 * c], &xyz[3 * (data[pos + 3 * t + c] % palette)], 12);
        if (!std::all_of(std::begin(tri), std::end(tri), [](float v) { return std::isfinite(v); })) continue;
        chunk.push(tri);
        if (chunk.full()) {
            decimator.push(chunk, emit);
            chunk.clear();
        }
    }
    if (!chunk.empty()) decimator.push(chunk, emit);
    decimator.finish(emit);
    if (out_count != decimator.stats().triangles_out) __builtin_trap();
    return 0;
}
