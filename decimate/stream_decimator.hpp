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

#include "decimate/attributes.hpp"
#include "decimate/emit.hpp"
#include "decimate/stats.hpp"
#include "io/chunk.hpp"
#include "io/input_count.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>

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
    // seams are decimated once both sides have been read: collapses along the seams first
    // (HalfEdgeBuffer::full_resolution_first), then, if the target needs more, anywhere.
    kSeams,
};

// The in-core buffer a decimator has unless told otherwise (Options::buffer_triangles): about
// 230 MB of address space reserved for positions only (reserved_bytes()).
inline constexpr size_t kDefaultBufferTriangles = 400000;

// The seam pass's buffer (Part::kSeams) for ranges decimated through `range_buffer` triangles
// each: a quarter of it, but the whole of it up to kSeamBufferTriangles (about 13 MB resident).
inline constexpr size_t kSeamBufferTriangles = 65536;
constexpr size_t seam_pass_buffer(size_t range_buffer) {
    return std::max(range_buffer / 4, std::min(range_buffer, kSeamBufferTriangles));
}

struct Options {
    double ratio = 0.1;              // p in (0, 1]: output = round(p · input)
    std::optional<uint64_t> target;  // exact output triangle count instead of ratio
    // N_max, in-core capacity (≥ 16)
    size_t buffer_triangles = kDefaultBufferTriangles;
    uint64_t seed = 1;               // draws the candidates of forced writes
    double weld_eps = 0;             // 0: exact welding; > 0: grid cell size (absolute)
    std::optional<int> sorted_axis;  // 0,1,2 when the input is sorted on it (either direction)
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

class StreamDecimator {
public:
    // `input_triangle_count` is the reader's count when known; Options::target needs it.
    // Options outside their ranges, or that do not fit together or with the count, throw
    // io::OptionError naming the setting and the value; so does an attribute layout of more than
    // kMaxAttributeComponents. Allocates every buffer once, std::bad_alloc when refused;
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
    // and writing to `out` as the schedule demands. Preconditions, std::invalid_argument before
    // reading any triangle when broken: every coordinate is finite (NaN/inf corners can be
    // neither welded nor finalized; io::TriangleInput drops them with BadTriangles::kDrop), and
    // the chunk carries the attribute layout's channels.
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
    // Part::kRange: the end of the range. Decimates what can be decimated and writes it to
    // `interior` (faces with no corner left on P_in; push() writes there too), each vertex on
    // P_in counting for one of the faces on P_in, the face the seam pass removes with it
    // (range_end_budget in schedule.hpp), then the
    // faces with a corner on P_in, as they are (their P_in corners keep their input positions):
    // those read in the first half of the range to `first_seam` (on streaming input they border
    // the range before), the others to `last_seam`. Each output is flushed; a triangle written to
    // `interior` stands for 1/ratio input triangles, one written to a seam for one.
    void finish_range(const Emit& interior, const Emit& first_seam, const Emit& last_seam);

    // Movable (a decimator moved from may only be destroyed or assigned to), not copyable.
    StreamDecimator(StreamDecimator&&) noexcept;
    StreamDecimator& operator=(StreamDecimator&&) noexcept;
    ~StreamDecimator();

    const Stats& stats() const;
    // round(ratio · input_triangle_count): the output size finish() lands on.
    static uint64_t expected_output(double ratio, uint64_t input_triangle_count);
    // The address space a decimator with a buffer of `buffer_triangles` reserves (the buffer,
    // hash tables and collapse queue); see docs/decimation.md for what becomes resident.
    static size_t reserved_bytes(size_t buffer_triangles, const AttributeLayout& attributes = {});
    // The ratio in use (target / input count with Options::target, less what was dropped).
    double ratio() const;

private:
    // The buffer, queue, output and sweep state (stream_decimator.cpp): every triangle of a
    // chunk is read, decimated and written inside it.
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace meshstream::decimate
