// What a decimator reports at its end (StreamDecimator::stats()), and how the reports of a mesh
// decimated in ranges (Part::kRange, then Part::kSeams over their outputs) combine into the
// whole mesh's: each field has one rule, listed once (for_each_stats_field), and combine_ranges
// applies them. The library does not build while a field of Stats has no rule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

namespace meshstream::decimate {

struct Stats {
    uint64_t triangles_in = 0;
    uint64_t triangles_out = 0;
    uint64_t target_triangles = 0;  // round(p·N_in) or --target (known at finish)
    size_t buffer_capacity = 0;
    size_t peak_buffer_triangles = 0;
    size_t peak_vertices = 0;
    uint64_t collapses = 0;
    uint64_t forced_writes = 0;      // written while touching P_in (buffer stuck)
    uint64_t premature_writes = 0;   // written before R reached p (decimation stalled)
    uint64_t degenerate_passed = 0;  // repeated corners in the input: passed through
    uint64_t weld_dropped = 0;       // distinct corners that --weld merged: dropped
    uint64_t nonmanifold_edges = 0;  // half-edges frozen as non-manifold
    uint64_t boundary_edges = 0;     // edges without a partner: holes, borders, cracks
    uint64_t vertices_merged = 0;    // vertices that absorbed other positions (--weld)
    uint64_t vertices_finalized_by_sweep = 0;
    int sweep_direction = 0;       // sorted input: +1 ascending, −1 descending, 0 not yet seen
    uint64_t sort_violations = 0;  // triangles reaching behind the sweep (sweep then stops)
    uint64_t orphans_evicted = 0;
    uint64_t vertices_moved = 0;           // moved to their quadric optimum when written
    uint64_t seam_vertices = 0;            // vertices whose corners disagree (kept in place)
    uint64_t attribute_values_zeroed = 0;  // non-finite channel values read as 0
    bool no_valid_collapse_left = false;   // the end's scan of every half-edge found none valid

    friend bool operator==(const Stats&, const Stats&) = default;
};

// How combine_ranges forms a field of the whole mesh's Stats.
enum class Combine : uint8_t {
    kSeamPass,        // the seam pass's: it made the output
    kRangesSum,       // the sum over the ranges (the seam pass's own left out)
    kAllSum,          // the seam pass's plus the sum over the ranges: work done in each
    kRangesMax,       // the largest of the ranges' (they ran side by side, each in its own buffer)
    kFirstRange,      // the first range's
    kBufferCapacity,  // the buffer each range was given (combine_ranges' argument)
};
template <Combine rule>
using CombineRule = std::integral_constant<Combine, rule>;

// Calls f(&Stats::field, CombineRule<rule>{}) once for every field of Stats, in declaration order.
template <typename F>
constexpr void for_each_stats_field(F&& f) {
    f(&Stats::triangles_in, CombineRule<Combine::kRangesSum>{});  // the seam pass reads their output
    f(&Stats::triangles_out, CombineRule<Combine::kSeamPass>{});
    f(&Stats::target_triangles, CombineRule<Combine::kSeamPass>{});
    f(&Stats::buffer_capacity, CombineRule<Combine::kBufferCapacity>{});
    f(&Stats::peak_buffer_triangles, CombineRule<Combine::kRangesMax>{});
    f(&Stats::peak_vertices, CombineRule<Combine::kRangesMax>{});
    f(&Stats::collapses, CombineRule<Combine::kAllSum>{});
    // The seam pass's buffer holds the ranges' output, not the input: what it forces out or
    // writes early, and what its input shows, does not describe the input.
    f(&Stats::forced_writes, CombineRule<Combine::kRangesSum>{});
    f(&Stats::premature_writes, CombineRule<Combine::kRangesSum>{});
    f(&Stats::degenerate_passed, CombineRule<Combine::kRangesSum>{});
    f(&Stats::weld_dropped, CombineRule<Combine::kAllSum>{});
    f(&Stats::nonmanifold_edges, CombineRule<Combine::kRangesSum>{});
    f(&Stats::boundary_edges, CombineRule<Combine::kSeamPass>{});  // of the output's mesh
    f(&Stats::vertices_merged, CombineRule<Combine::kRangesSum>{});
    f(&Stats::vertices_finalized_by_sweep, CombineRule<Combine::kRangesSum>{});
    f(&Stats::sweep_direction, CombineRule<Combine::kFirstRange>{});  // the seam pass does not sweep
    f(&Stats::sort_violations, CombineRule<Combine::kRangesSum>{});
    f(&Stats::orphans_evicted, CombineRule<Combine::kAllSum>{});
    f(&Stats::vertices_moved, CombineRule<Combine::kAllSum>{});
    // Met by a range, and again by the seam pass where a seam vertex lies on a cut.
    f(&Stats::seam_vertices, CombineRule<Combine::kAllSum>{});
    f(&Stats::attribute_values_zeroed, CombineRule<Combine::kAllSum>{});
    f(&Stats::no_valid_collapse_left, CombineRule<Combine::kSeamPass>{});  // it made the output
}

// The number of fields for_each_stats_field visits.
constexpr size_t stats_rule_count() {
    size_t n = 0;
    for_each_stats_field([&n](auto, auto) { ++n; });
    return n;
}

// The whole mesh's Stats from the seam pass's (`seams`, after finish_at()) and the ranges' (in
// range order; at least one) when each range was given a buffer of `buffer_capacity` triangles.
// Throws std::invalid_argument when `ranges` is empty.
Stats combine_ranges(const Stats& seams, std::span<const Stats> ranges, size_t buffer_capacity);

}  // namespace meshstream::decimate
