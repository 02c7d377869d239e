// `meshstream decimate --threads N` (engine::decimate_file with DecimateSettings::threads): one
// input file decimated by N stream decimators at once.
// The input's triangles are cut into N contiguous ranges; each range is decimated by a stream
// decimator of its own (decimate::Part::kRange: the vertices still open at the end of a range may
// be shared with another range, so they stay where they were read), and its output spooled to a
// temporary file. The calling thread runs the seam pass beside them: a stream decimator
// (decimate::Part::kSeams) over the ranges' outputs in range order, which decimates the
// full-resolution strips along the seams down to the ratio once both sides have been read, lands
// on the exact target count and writes the result. Output is a function of the input, the options
// and the number of ranges only (never of timing, nor of where a range ran).
//
// A range runs on a thread of this process, or in another process (`meshstream-mpi`, one range
// per MPI rank: RangeProcesses) that sends its pieces here as it makes them.
//
// Each range re-opens the input. On threads of this process, a range of an unsorted binary STL
// or triangle stream with a count (fixed-size records in a file that can seek:
// io::Reader::select_triangles) goes straight to the record where its triangles
// start if no triangle before it is dropped, and reads on from there; once the ranges before it
// have read theirs without a drop it is confirmed (the seam pass reads none of its output before
// that), else it starts again as below. Any other range (another input, a sorted one: a range
// needs the span of the triangles before it, or a range run elsewhere) reads its way to its
// range; that reading is the serial part besides the seam pass. Either way range k holds the same
// triangles of the read loop.
// Memory: N decimators of the
// buffer's triangles, N readers, the seam pass's decimator of a quarter of the buffer
// (decimate::seam_pass_buffer); the ranges' outputs wait on disk (36 bytes a triangle, plus the
// channels carried: io::TriangleRecords), not in memory.
#pragma once

#include "decimate/stream_decimator.hpp"
#include "engine/progress.hpp"
#include "engine/warnings.hpp"
#include "io/triangle_input.hpp"
#include "io/triangle_records.hpp"

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meshstream::engine {

// The smallest --buffer that is cut into ranges. A smaller buffer asks for little memory, which
// ranges would multiply, and its seam pass would hold two seams at full resolution in less room
// than one range's stream front takes.
inline constexpr size_t kMinRangeBuffer = 16384;

// How many ranges `threads` threads cut an input of `triangles` into: every range holds at least
// `buffer` triangles (an input that about fits in one buffer gains nothing from a cut), so an
// input of fewer than 2·buffer triangles, or a buffer below kMinRangeBuffer, is decimated whole.
unsigned range_count(unsigned threads, uint64_t triangles, size_t buffer);

// The pieces of a range's output: the decimated rest, the faces on P_in read first (along the
// seam with the range before), the faces on P_in read last (along the seam with the range after).
// The seam pass reads them in this order: the rest as the range makes it, the seam faces, which
// the range makes at its end, after it. The strip the range before left along the seam waits
// open in the seam pass's buffer meanwhile (the rest reaches the seam only through this range's
// own seam faces), and the two strips are joined when the first seam faces come.
enum class Piece : uint8_t { kFirstSeam, kInterior, kLastSeam };

// How a range ended (besides an exception).
struct RangeOutcome {
    decimate::Stats stats;   // its decimator's, when it ran to its end
    bool forced = false;     // stopped at a forced write (RangesJob::stop_at_forced_write)
    uint64_t forced_at = 0;  // triangles of the range read by then
    // Set when it ran to its end having read from its own record on (a binary STL's range:
    // io::TriangleInput::select_triangles), with what its read loop read and dropped; when
    // every range did, the ranges' sums are the input's.
    bool selected = false;
    uint64_t read = 0;        // the input's triangles in the range
    uint64_t non_finite = 0;  // of those, dropped for a NaN or infinite coordinate
    uint64_t degenerate = 0;  // dropped for two corners at the same position
};

// Where a range's output goes, wherever the range runs.
class RangeSink {
public:
    virtual ~RangeSink() = default;
    // One chunk of `piece`, each triangle standing for `weight` input triangles.
    virtual void append(const io::TriangleChunk& chunk, double weight, Piece piece) = 0;
    // The range's triangles pushed into its decimator so far.
    virtual void progress(uint64_t decimated) = 0;
    // Last: how the range ended, or its exception (null when it ended normally or was stopped).
    virtual void close(const RangeOutcome& outcome, std::exception_ptr error) = 0;
};

struct RangesJob {
    // Opens the input afresh (the read loop with decimate's policy, positions only); called once
    // on each range's thread.
    std::function<io::TriangleInput()> open;
    // Makes a decimator (the command's, which says what a refused --buffer reservation costs).
    std::function<std::unique_ptr<decimate::StreamDecimator>(const decimate::Options&)> make_decimator;
    std::string tmpdir;  // for the ranges' spools
    // The channels carried besides positions (the decimators' attribute layout's): read, spooled
    // and sent with each triangle.
    io::Channels channels;
    decimate::Options options;       // the decimator's: ratio (not target), buffer, seed, weld, sorted axis
    std::optional<uint64_t> target;  // --target: the seam pass lands on it (else round(ratio · input))
    uint64_t cut_triangles = 0;      // the count the ranges are cut from (the last takes the rest)
    unsigned ranges = 2;
    // --sort auto: stop at the first forced write in any range (the input is to be sorted).
    bool stop_at_forced_write = false;
    // The seam pass starts only once every range is done (an output that cannot be taken back
    // while a forced write may still call for a sort).
    bool seams_after_ranges = false;
    // Ranges 0 .. remote_ranges-1 run elsewhere (RangeProcesses); the rest on threads here. The
    // last range, whose read loop counts the whole input, always runs here.
    unsigned remote_ranges = 0;
    // With remote ranges: called on a thread of its own with their sinks, in range order; puts
    // what the ranges send into them and returns once every one is closed. A remote range that
    // fails or stops at a forced write sets `stop`; once `stop` is set, the ranges still running
    // are asked to stop.
    std::function<void(std::span<RangeSink* const>, std::atomic<bool>& stop)> receive_remote;
};

// What the processes of a spread-out job (meshstream-mpi) share before the ranges start: the
// job as process 0 planned it. Trivially copyable: every process runs the same build.
struct RangePlan {
    decimate::Options options;  // RangesJob::options
    uint64_t cut_triangles = 0;
    unsigned ranges = 0;
    bool stop_at_forced_write = false;
};

// The processes of one decimation spread over processes (meshstream-mpi): process 0 runs the
// command, the seam pass and the last range; process r (1 .. ranges-1) decimates range r-1 and
// sends its pieces to process 0 as it makes them.
class RangeProcesses {
public:
    virtual ~RangeProcesses() = default;
    virtual unsigned count() const = 0;
    virtual unsigned rank() const = 0;
    // Process 0, once: the plan to every other process (none: there is nothing for them to do).
    virtual void share_plan(const std::optional<RangePlan>& plan) = 0;
    // Every other process, once: the plan process 0 shared.
    virtual std::optional<RangePlan> receive_plan() = 0;
    // Process 0: RangesJob::receive_remote for the ranges of processes 1 .. sinks.size(), whose
    // triangles carry `channels` (RangesJob::channels).
    virtual void receive(std::span<RangeSink* const> sinks, std::atomic<bool>& stop, const io::Channels& channels) = 0;
    // Every other process: the sink that sends its range to process 0; sets `stop` once process
    // 0 asks the range to stop. Returns once process 0 has received everything it sent.
    virtual void send(const io::Channels& channels,
                      const std::function<void(RangeSink&, std::atomic<bool>& stop)>& run_range) = 0;
};

struct RangesResult {
    bool stopped_at_forced_write = false;
    uint64_t forced_write_at = 0;  // stopped: input triangles before the first range's forced write
    decimate::Stats stats;         // the ranges' and the seam pass's, summed as the summary shows them
    decimate::Stats seams;         // the seam pass's own
    double ratio = 0;
    // The read loop over the whole input (the last range reads it all, or the ranges' figures
    // summed when each read its own: RangeOutcome::selected): counts, drops, header.
    io::InputCount count;
    DroppedTriangles dropped;
    io::MeshHeader end_header;
};

// Decimates range k of `job` on this thread into `sink` (closed at the end, with the exception
// if it failed), stopping between chunks once `stop` is set.
void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop);

// Runs the job: ranges on their threads (or elsewhere: RangesJob::remote_ranges), the seam pass on this one writing to
// `emit`, updating `progress` with the input triangles decimated so far. An exception on any thread (the first bad
// input in the file's order, whichever range met it) is rethrown here once every thread has stopped; nothing is written
// after it. Once `progress` says cancelled(), every range stops between chunks and Cancelled is thrown.
RangesResult decimate_in_ranges(const RangesJob& job, const decimate::Emit& emit, ProgressSink& progress);

}  // namespace meshstream::engine
