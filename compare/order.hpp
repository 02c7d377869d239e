// How far a triangle stream is from the order the stream decimator assumes: the stream's
// *width*, as in the streaming-mesh literature (Isenburg & Lindstrom, "Streaming Meshes",
// 2005, who measure the front of active vertices; here counted in triangles, the decimator's
// buffer unit). Definitions, for triangles t_0 .. t_{n-1} in file order:
//   - a vertex is a position (exact float equality, -0 = +0), as STL welding identifies it;
//   - last(v) = index of the last triangle with a corner at v;
//   - L(i) = max over the corners v of t_i of last(v): after reading t_L(i), no triangle
//     adjacent to t_i through a vertex is still to come;
//   - t_i is *open* at time j (after t_j was read) when i <= j < L(i);
//   - width = max over j of the number of triangles open at time j.
// A buffer of `width` triangles can hold every triangle until all its neighbours arrived, so
// a decimator whose --buffer is at least the width never has to force-write an unfinished
// triangle. A shuffled file has a width close to its triangle count; a sorted one about the
// size of the sweep front.
//
// Method (one pass, bounded memory): a hash table maps each tracked vertex to its last use;
// tracked vertices are those of *sampled* triangles, and L(i) is found for sampled triangles
// only. While everything fits in the budget every triangle is sampled and the width is exact.
// When the table or the sample list would exceed the budget, the sampling rate halves
// (triangle i stays sampled iff a hash of i has `level` zero low bits, so samples are nested)
// and dropped triangles release their vertices. The width is then estimated as max_j count/p.
// Each count is a sum of independent-like Bernoulli(p) draws with standard deviation
// σ = sqrt(width·(1-p)/p); taking the maximum over many noisy, correlated counts biases the
// estimate upward by up to about 2σ (measured: +1.9σ on a shuffled 80 000-triangle grid at
// p = 1/32), so the reported error is ±3σ, and an error tends toward overestimating (the safe
// side for "would this buffer suffice"). Memory: at most the budget (half for 24-byte table
// slots at load <= 1/2, a quarter more while the table grows, a fifth for 48-byte samples).
#pragma once

#include "io/chunk.hpp"
#include "io/format.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace meshstream::compare {

struct OrderReport {
    uint64_t triangles = 0;
    uint64_t width = 0;                  // estimate; exact when sample_rate == 1
    double width_error = 0;              // ≈95% half-width of the estimate (0 when exact)
    double sample_rate = 1;              // fraction of triangles tracked (a power of 1/2)
    uint64_t width_at = 0;               // triangle index at which the width is reached
    std::array<uint64_t, 3> descents{};  // times the sort key (minimum x, y, z) decreased
    bool exact() const { return sample_rate == 1.0; }
    // The axis whose key decreased least often (the likely sort axis), 0..2.
    int best_axis() const;
};

enum class BufferVerdict { kSuffices, kTooSmall, kUncertain };
// The buffer decimate needs per triangle of width at decimation ratio `ratio`: the open
// triangles plus room for the decimated region behind the front, which grows with the ratio.
// It also depends on the mesh and the sort axis, so this is an estimate. Measured (the least
// buffer without forced writes ÷ width) at ratios 0.01 / 0.1 / 0.5 / 0.9: the bunny sorted
// along x (width 830) 1.08 / 1.31 / 1.64 / 1.93, along y (933) 1.47 / 1.48 / 2.22 / 2.61, the
// 1 M generated mesh (5 858) 1.06 / 1.18 / 1.60 / 1.91; open 600 × 600 height-field patches
// (720 000 triangles), flagged as sorted (1 203) 2.15 / 2.15 / 2.66 / 3.83, sorted by
// `meshstream sort` after a shuffle (1 791) 1.91 / 1.91 / 1.91 / 2.66. 2.2 + 2·ratio covers
// them all (generously for closed meshes at small ratios).
inline double buffer_per_width(double ratio) { return 2.2 + 2 * ratio; }
// The buffer that suffices for decimating at `ratio`: buffer_per_width × (width + its error).
uint64_t buffer_needed(const OrderReport& report, double ratio);
// Whether a decimation buffer of `buffer_triangles` suffices at `ratio`: kSuffices when it
// holds buffer_needed(), kTooSmall when it holds less than the width (minus its error),
// kUncertain in between.
BufferVerdict buffer_verdict(const OrderReport& report, uint64_t buffer_triangles, double ratio);

// Measures a stream chunk by chunk (chunks in, no I/O). Memory: at most `memory_budget_bytes`
// (at least 1 MiB is used as the floor).
class OrderMeter {
public:
    explicit OrderMeter(uint64_t memory_budget_bytes = io::kDefaultMemoryBudget);
    ~OrderMeter();
    OrderMeter(const OrderMeter&) = delete;
    OrderMeter& operator=(const OrderMeter&) = delete;

    void add(const io::TriangleChunk& chunk);
    // Computes the report; the meter is spent afterwards.
    OrderReport finish();

private:
    struct Table;
    struct Sample {
        uint64_t index;
        uint32_t corner[9];  // canonical position bits of the three corners
    };
    void add_triangle(const float* xyz);
    void downsample();

    uint64_t budget_bytes_;
    uint64_t max_samples_;
    int level_ = 0;  // sampling rate 2^-level
    uint64_t count_ = 0;
    std::unique_ptr<Table> table_;
    std::vector<Sample> samples_;
    std::array<uint32_t, 3> prev_key_{};
    std::array<uint64_t, 3> descents_{};
};

// Reads a whole mesh file and measures it. Returns nullopt for "-" (stdin cannot be read
// again); throws io::Error on bad input.
std::optional<OrderReport> measure_file_order(const std::string& path, std::string_view from,
                                              const io::ReadOptions& options);

}  // namespace meshstream::compare
