// meshstream's stream decimator: Wu & Kobbelt, "A Stream Algorithm for the Decimation of
// Massive Meshes", Graphics Interface 2003. Triangle chunks go in, decimated triangle chunks
// (with stable vertex ids) come out while the input is still being read; memory is fixed by
// the buffer capacity, independent of input and output size. No file I/O here.
//
// Beyond the paper: non-manifold, duplicate, mis-oriented and degenerate input is frozen and
// passed through; on input sorted along an axis, hole boundaries the sweep has left behind
// are finalized so that scans full of holes decimate in a small buffer; when the buffer is
// full of triangles that can be neither decimated nor written, triangles are force-written
// and counted instead of failing.
#pragma once

#include "decimate/attribute_store.hpp"
#include "decimate/collapse_queue.hpp"
#include "decimate/halfedge_buffer.hpp"
#include "decimate/random.hpp"
#include "decimate/writing.hpp"
#include "io/chunk.hpp"
#include "io/input_count.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace meshstream::decimate {

// What a decimator's stream is (parallel decimation cuts a mesh into contiguous ranges of
// triangles, decimates each in its own decimator and joins them in a seam pass).
enum class Part : uint8_t {
    kWhole,  // the whole mesh (finish())
    // One range of the mesh (finish_range()): the vertices still on P_in at its end may be shared
    // with another range, so they are never finalized: they and their faces come out as read
    // (positions, at full resolution). Faces with a corner on P_in stand for themselves in the
    // schedule (schedule.hpp, part_budget), the rest are held at the ratio.
    kRange,
    // The seam pass over the ranges' outputs in range order (push() with weights, finish_at()):
    // each triangle stands for the input triangles its range said, so where the ranges' outputs
    // are already at the ratio nothing is decimated, and the full-resolution strips along the
    // seams are decimated down to it once both sides have been read.
    kSeams,
};

// TEMPORARY until the decimate constants land.
inline constexpr size_t kDefaultBufferTriangles = 400000;

struct Options {
    double ratio = 0.1;                // p in (0, 1]: output = round(p · input)
    std::optional<uint64_t> target;    // exact output triangle count instead of ratio
    size_t buffer_triangles = 400000;  // N_max, in-core capacity (≥ 16)
    uint64_t seed = 1;                 // draws the candidates of forced writes
    double weld_eps = 0;               // 0: exact welding; > 0: grid cell size (absolute)
    std::optional<int> sorted_axis;    // 0,1,2 when the input is sorted on it (either direction)
    // The order is known exactly: ascending by each triangle's minimum coordinate along
    // sorted_axis, as `meshstream sort` writes it (the file's own flag says so). The sweep then
    // needs no margin, and one triangle whose minimum descends shows the order is not that.
    bool sorted_by_minimum = false;
    size_t output_chunk_triangles = io::TriangleChunk::kDefaultCapacity;  // ≥ 1
    Part part = Part::kWhole;
    // kRange on sorted input: the interval along sorted_axis covered by every triangle before
    // this range. A vertex inside it may be shared with an earlier range: the sweep leaves it
    // open (it finalizes only vertices no other range can reach).
    std::optional<std::array<double, 2>> earlier_span;
};

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
};

class StreamDecimator {
public:
    // `input_triangle_count` is the reader's count when known; Options::target needs it.
    // Options outside their ranges throw std::invalid_argument. Allocates every buffer once;
    // reserved_bytes() tells how much (about 580 bytes reserved per buffer triangle).
    //
    // With `attributes` carrying channels (AttributeLayout::any()), the decimator reads them from
    // every chunk (which must have them), rates collapses by geometric plus attribute error,
    // keeps seams (attributes.hpp) and emits them; else it reads and emits positions only.
    StreamDecimator(const Options& options, std::optional<uint64_t> input_triangle_count,
                    const AttributeLayout& attributes = {});
    // The same for input that passes a read loop (io::TriangleInput) which may drop triangles
    // on the way: `input` (observed, must outlive this) says what its header promised and how
    // many were dropped so far. With Options::target the ratio becomes target / (promised −
    // dropped so far), so the output lands on the target when the dropped ones come early or
    // spread through the input; ones that all come late leave it short (the mesh before them
    // was decimated for more input).
    StreamDecimator(const Options& options, const io::InputCount& input, const AttributeLayout& attributes = {});

    // Reads every triangle of `in` (positions, and the attribute layout's channels), decimating
    // and writing to `out` as the schedule demands. Every coordinate must be finite, else it
    // throws std::invalid_argument before reading any: NaN/inf corners can be neither welded
    // nor finalized (the commands drop them first with tools::TriangleFilter).
    void push(const io::TriangleChunk& in, const Emit& out);
    // End of input: decimates to the target (as close as the mesh allows: see Stats), writes
    // the rest, flushes `out`.
    // Call once; push() or finish() after it throw std::logic_error.
    void finish(const Emit& out);
    // Part::kSeams: pushes `in` with each triangle standing for `weight` input triangles in the
    // schedule (push() above weighs 1).
    void push(const io::TriangleChunk& in, double weight, const Emit& out);
    // Part::kSeams: the end of input, landing on `target` triangles in total (the ratio over
    // the ranges' input counts, or --target); otherwise as finish().
    void finish_at(uint64_t target, const Emit& out);
    // Part::kRange: the end of the range. Decimates what can be decimated to the ratio and writes
    // it to `interior` (faces with no corner left on P_in; push() writes there too), then the
    // faces with a corner on P_in, as they are (their P_in corners keep their input positions):
    // those read in the first half of the range to `first_seam` (on streaming input they border
    // the range before), the others to `last_seam`. Each output is flushed; a triangle written to
    // `interior` stands for 1/ratio input triangles, one written to a seam for one.
    void finish_range(const Emit& interior, const Emit& first_seam, const Emit& last_seam);

    const Stats& stats() const { return stats_; }
    // round(ratio · input_triangle_count): the output size finish() lands on.
    static uint64_t expected_output(double ratio, uint64_t input_triangle_count);
    // The address space a decimator with a buffer of `buffer_triangles` reserves (the buffer,
    // hash tables and collapse queue); see docs/decimation.md for what becomes resident.
    static size_t reserved_bytes(size_t buffer_triangles, const AttributeLayout& attributes = {});
    // The ratio in use (target / input count with Options::target, less what was dropped).
    double ratio() const { return ratio_; }

private:
    StreamDecimator(const Options& options, io::InputCount own, const io::InputCount* input,
                    const AttributeLayout& attributes);
    void read_triangle(const io::TriangleChunk& in, size_t i, const uint64_t hashes[3], const Emit& out);
    void make_room(const Emit& out);
    void write_one(const Emit& out, bool allow_forced);
    void sweep();
    void track_sweep(const float tri[9]);
    void follow_dropped();
    double budget() const;
    void decimate_final(size_t keep);  // down to `keep` faces in core (kRange: follows budget())
    void collect_stats();

    Options options_;
    io::InputCount own_count_;     // the count given to the first constructor
    const io::InputCount* input_;  // own_count_ or the caller's read loop's
    double ratio_;
    HalfEdgeBuffer buffer_;
    std::unique_ptr<AttributeStore> attributes_;  // null for positions only
    std::vector<double> face_scalars_;            // the triangle being read's (with attributes_)
    CollapseQueue queue_;
    Rng rng_;
    TriangleOutput output_;
    uint64_t next_id_ = 0;
    double weight_ = 1;       // input triangles each triangle being read stands for (kSeams)
    double represented_ = 0;  // input triangles the triangles read stand for (kRange, kSeams)
    Stats stats_;
    bool finished_ = false;

    // Sorted input (--sorted-axis): FIFO of vertices entering P_in with their coordinate.
    struct SweepEntry {
        float coordinate;
        uint32_t vertex, generation;
    };
    std::unique_ptr<SweepEntry[]> sweep_queue_;
    size_t sweep_capacity_ = 0, sweep_head_ = 0, sweep_size_ = 0;
    // Ascending input: the front is the largest triangle minimum read (lo_max_); descending:
    // the smallest triangle maximum (hi_min_). The direction is decided once the front has
    // left the first triangle by more than two margins.
    double lo_max_ = -INFINITY, hi_min_ = INFINITY, sweep_margin_ = 0;
    double first_lo_ = 0, first_hi_ = 0;
    bool sweep_started_ = false, sweep_enabled_ = true;
    std::optional<double> swept_to_;  // threshold of the last sweep that finalized vertices
};

}  // namespace meshstream::decimate
