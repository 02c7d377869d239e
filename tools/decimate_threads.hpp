// `meshstream decimate --threads N`: one input file decimated by N stream decimators at once.
// The input's triangles are cut into N contiguous ranges; each range is decimated on its own
// thread by a stream decimator of its own (decimate::Part::kRange: the vertices still open at
// the end of a range may be shared with another range, so they stay where they were read), and
// its output spooled to a temporary file. The calling thread runs the seam pass beside them: a
// stream decimator (decimate::Part::kSeams) over the ranges' outputs in range order, which
// decimates the full-resolution strips along the seams down to the ratio once both sides have
// been read, lands on the exact target count and writes the result. Output is a function of the
// input, the options and the number of ranges only (never of timing).
//
// Each range re-opens the input and reads its way to its range (no format has to seek): the
// reading before a range is the serial part besides the seam pass. Memory: N decimators of
// --buffer triangles, N readers, the seam pass's decimator of a quarter of --buffer; the ranges'
// outputs wait on disk (36 bytes a triangle), not in memory.
#pragma once

#include "decimate/stream_decimator.hpp"
#include "io/triangle_input.hpp"
#include "tools/common.hpp"
#include "tools/input_filter.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace meshstream::tools {

// The smallest --buffer that is cut into ranges. A smaller buffer asks for little memory, which
// ranges would multiply, and its seam pass would hold two seams at full resolution in less room
// than one range's stream front takes.
inline constexpr size_t kMinRangeBuffer = 16384;

// How many ranges `threads` threads cut an input of `triangles` into: every range holds at least
// `buffer` triangles (an input that about fits in one buffer gains nothing from a cut), so an
// input of fewer than 2·buffer triangles, or a buffer below kMinRangeBuffer, is decimated whole.
unsigned range_count(unsigned threads, uint64_t triangles, size_t buffer);

// The seam pass's buffer for ranges decimated through `buffer` triangles each: a quarter of it,
// but the whole of it up to 65 536 triangles (about 13 MB resident).
size_t seam_buffer(size_t buffer);

struct RangesJob {
    // Opens the input afresh (the read loop with decimate's policy, positions only); called once
    // on each range's thread.
    std::function<io::TriangleInput()> open;
    // Makes a decimator (the command's, which says what a refused --buffer reservation costs).
    std::function<std::unique_ptr<decimate::StreamDecimator>(const decimate::Options&)> make_decimator;
    std::string tmpdir;              // for the ranges' spools
    decimate::Options options;       // the decimator's: ratio (not target), buffer, seed, weld, sorted axis
    std::optional<uint64_t> target;  // --target: the seam pass lands on it (else round(ratio · input))
    uint64_t cut_triangles = 0;      // the count the ranges are cut from (the last takes the rest)
    unsigned ranges = 2;
    // --sort auto: stop at the first forced write in any range (the input is to be sorted).
    bool stop_at_forced_write = false;
    // The seam pass starts only once every range is done (an output that cannot be taken back
    // while a forced write may still call for a sort).
    bool seams_after_ranges = false;
};

struct RangesResult {
    bool stopped_at_forced_write = false;
    uint64_t forced_write_at = 0;  // stopped: input triangles before the first range's forced write
    decimate::Stats stats;         // the ranges' and the seam pass's, summed as the summary shows them
    decimate::Stats seams;         // the seam pass's own
    double ratio = 0;
    // The read loop over the whole input (the last range reads it all): counts, drops, header.
    io::InputCount count;
    DroppedTriangles dropped;
    io::MeshHeader end_header;
};

// Runs the job: ranges on their threads, the seam pass on this one writing to `emit`, calling
// `progress` with the input triangles decimated so far. An exception on any thread (the first
// bad input in the file's order, whichever range met it) is rethrown here once every thread has
// stopped; nothing is written after it.
RangesResult decimate_in_ranges(const RangesJob& job, const decimate::Emit& emit,
                                const std::function<void(uint64_t)>& progress);

}  // namespace meshstream::tools
