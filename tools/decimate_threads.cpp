// Parallel decimation in ranges with a seam pass: see decimate_threads.hpp.
#include "tools/decimate_threads.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace meshstream::tools {
namespace {

// The pieces of a range's output, in the order the seam pass reads them: the faces on P_in read
// first (along the seam with the range before), the decimated rest, the faces on P_in read last
// (along the seam with the range after). Read in this order, each seam's two strips meet in the
// seam pass at once, and they are joined before the buffer has to hold anything else.
enum class Piece : uint8_t { kFirstSeam, kInterior, kLastSeam };

// One range's output on its way to the seam pass: positions in a temporary file, and for each
// chunk its piece, triangle count and the input triangles each of them stands for. Appended to by
// the range's thread, read by the seam pass's.
class RangeSpool {
public:
    explicit RangeSpool(const std::string& tmpdir) : file_(tmpdir, "meshstream-range") {}

    // The range's thread: one chunk of `piece`, each triangle standing for `weight` input triangles.
    void append(const io::TriangleChunk& chunk, double weight, Piece piece) {
        file_.write(chunk.xyz().data(), chunk.xyz().size_bytes());
        file_.flush();  // the seam pass reads the file directly (pread), not this object's buffer
        const std::lock_guard lock(mutex_);
        chunks_.push_back({written_, chunk.size(), weight, piece});
        written_ += chunk.xyz().size_bytes();
        changed_.notify_all();
    }
    // The range's thread, last: its outcome (null when it ended normally or was stopped).
    void close(std::exception_ptr error) {
        const std::lock_guard lock(mutex_);
        done_ = true;
        error_ = std::move(error);
        changed_.notify_all();
    }
    // The seam pass: the next chunk of `piece` into `chunk` (capacity at least the ranges' output
    // chunks) and its weight; false once the range is closed and has no more of it, or when
    // `stop` is set. Calls `waiting` now and then while it waits.
    bool next(Piece piece, io::TriangleChunk& chunk, double& weight, const std::atomic<bool>& stop,
              const std::function<void()>& waiting) {
        Chunk c;
        {
            std::unique_lock lock(mutex_);
            size_t& i = cursor_[size_t(piece)];
            for (;;) {
                while (i < chunks_.size() && chunks_[i].piece != piece) ++i;
                if (stop) return false;
                if (i < chunks_.size()) break;
                if (done_) return false;
                changed_.wait_for(lock, std::chrono::milliseconds(100));
                lock.unlock();
                waiting();
                lock.lock();
            }
            c = chunks_[i++];
        }
        chunk.clear();
        const size_t bytes = c.triangles * 36;
        auto* dst = reinterpret_cast<char*>(chunk.xyz_storage());
        for (size_t got = 0; got < bytes;) {
            const ssize_t r = ::pread(file_.fd(), dst + got, bytes - got, off_t(c.offset + got));
            if (r < 0 && errno == EINTR) continue;
            if (r <= 0)
                throw io::Error(file_.path(), std::string("cannot read a range's spooled output back: ") +
                                                  (r < 0 ? std::strerror(errno) : "file shorter than written"));
            got += size_t(r);
        }
        chunk.resize(c.triangles);
        weight = c.weight;
        return true;
    }
    // Waits until the range is closed (or `stop`), calling `waiting` now and then.
    void wait_closed(const std::atomic<bool>& stop, const std::function<void()>& waiting) {
        std::unique_lock lock(mutex_);
        while (!done_ && !stop) {
            changed_.wait_for(lock, std::chrono::milliseconds(100));
            lock.unlock();
            waiting();
            lock.lock();
        }
    }
    // Once the range's thread is joined: its exception, if it failed.
    std::exception_ptr error() {
        const std::lock_guard lock(mutex_);
        return error_;
    }

private:
    struct Chunk {
        uint64_t offset = 0;
        size_t triangles = 0;
        double weight = 1;
        Piece piece = Piece::kInterior;
    };
    io::TempFile file_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<Chunk> chunks_;
    uint64_t written_ = 0;
    bool done_ = false;
    std::exception_ptr error_;
    size_t cursor_[3] = {0, 0, 0};  // the seam pass's: the next chunk of each piece to look at
};

// One range and what its thread found.
struct Range {
    uint64_t start = 0, end = 0;  // passed triangles [start, end) of the read loop
    std::unique_ptr<RangeSpool> spool;
    std::atomic<uint64_t> decimated{0};  // triangles of the range pushed so far
    std::atomic<bool> forced{false};     // stopped at a forced write (RangesJob::stop_at_forced_write)
    uint64_t forced_at = 0;              // triangles of the range read by then
    decimate::Stats stats;               // once finished
    // The last range reads the whole input: its read loop's figures are the input's.
    io::InputCount count;
    DroppedTriangles dropped;
    io::MeshHeader end_header;
};

void run_range(const RangesJob& job, unsigned k, Range& range, std::atomic<bool>& stop) {
    std::exception_ptr error;
    try {
        io::TriangleInput in = job.open();
        decimate::Options options = job.options;
        options.part = decimate::Part::kRange;
        // The triangles before the range are read past (no format has to seek); on sorted input
        // their span along the axis tells the sweep which vertices an earlier range may share.
        const int axis = options.sorted_axis.value_or(-1);
        double span_lo = std::numeric_limits<double>::infinity(), span_hi = -span_lo;
        io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, io::Channels{});
        io::TriangleChunk part(io::TriangleChunk::kDefaultCapacity, io::Channels{});
        uint64_t passed = 0;  // passed triangles of the read loop seen so far
        size_t first = 0;     // the range begins at this triangle of `chunk`
        bool straddles = false;
        while (passed < range.start && !stop) {
            if (!in.next(chunk)) break;
            const size_t skip = size_t(std::min<uint64_t>(chunk.size(), range.start - passed));
            if (axis >= 0)
                for (size_t i = 0; i < 3 * skip; ++i) {
                    const double v = chunk.xyz()[3 * i + size_t(axis)];
                    span_lo = std::min(span_lo, v);
                    span_hi = std::max(span_hi, v);
                }
            passed += skip;
            if (skip < chunk.size()) {
                first = skip;
                straddles = true;
            }
        }
        if (axis >= 0 && k > 0) options.earlier_span = std::array<double, 2>{span_lo, span_hi};
        const std::unique_ptr<decimate::StreamDecimator> decimator = job.make_decimator(options);
        const double weight = 1.0 / decimator->ratio();
        const decimate::Emit interior = [&](const io::TriangleChunk& c) {
            range.spool->append(c, weight, Piece::kInterior);
        };
        const decimate::Emit first_seam = [&](const io::TriangleChunk& c) {
            range.spool->append(c, 1.0, Piece::kFirstSeam);
        };
        const decimate::Emit last_seam = [&](const io::TriangleChunk& c) {
            range.spool->append(c, 1.0, Piece::kLastSeam);
        };
        // Pushes `c`; false at a forced write that stops the job.
        auto push = [&](const io::TriangleChunk& c) {
            decimator->push(c, interior);
            range.decimated += c.size();
            if (!job.stop_at_forced_write || decimator->stats().forced_writes == 0) return true;
            range.forced_at = range.decimated;
            range.forced = true;
            stop = true;
            return false;
        };
        bool going = !stop;
        if (straddles && going) {
            part.clear();
            for (size_t i = first; i < chunk.size() && passed < range.end; ++i, ++passed) part.push_copy(chunk, i);
            going = push(part);
        }
        while (going && passed < range.end && !stop && in.next(chunk)) {
            if (chunk.size() <= range.end - passed) {
                passed += chunk.size();
                going = push(chunk);
            } else {
                part.clear();
                for (size_t i = 0; passed < range.end; ++i, ++passed) part.push_copy(chunk, i);
                going = push(part);
            }
        }
        if (going && !stop) {
            decimator->finish_range(interior, first_seam, last_seam);
            range.stats = decimator->stats();
            if (k + 1 == job.ranges) {
                range.count = in.count();
                range.dropped = dropped_triangles(in);
                range.end_header = in.header();
            }
        }
    } catch (...) {
        // The first bad input in the file's order: every range reads the file from its start,
        // so each range that fails fails at the first error before its end.
        error = std::current_exception();
        stop = true;
    }
    range.spool->close(error);
}

}  // namespace

unsigned range_count(unsigned threads, uint64_t triangles, size_t buffer) {
    if (buffer < kMinRangeBuffer) return 1;
    return unsigned(std::max<uint64_t>(1, std::min<uint64_t>(threads, triangles / buffer)));
}

size_t seam_buffer(size_t buffer) { return std::max(buffer / 4, std::min<size_t>(buffer, 65536)); }

RangesResult decimate_in_ranges(const RangesJob& job, const decimate::Emit& emit,
                                const std::function<void(uint64_t)>& progress) {
    std::vector<std::unique_ptr<Range>> ranges;
    for (unsigned k = 0; k < job.ranges; ++k) {
        auto range = std::make_unique<Range>();
        range->start = job.cut_triangles * k / job.ranges;
        range->end =
            k + 1 == job.ranges ? std::numeric_limits<uint64_t>::max() : job.cut_triangles * (k + 1) / job.ranges;
        range->spool = std::make_unique<RangeSpool>(job.tmpdir);
        ranges.push_back(std::move(range));
    }
    // The seam pass: the ranges' outputs carry no sort order, and their welded positions meet
    // again on the same weld grid.
    decimate::Options seam_options = job.options;
    seam_options.part = decimate::Part::kSeams;
    seam_options.buffer_triangles = seam_buffer(job.options.buffer_triangles);
    seam_options.sorted_axis.reset();
    seam_options.sorted_by_minimum = false;
    seam_options.earlier_span.reset();
    const std::unique_ptr<decimate::StreamDecimator> seams = job.make_decimator(seam_options);

    std::atomic<bool> stop{false};
    std::vector<std::thread> threads;
    // Every thread is joined before this function returns or throws (stopped first on a throw).
    struct Joiner {
        std::vector<std::thread>& threads;
        std::atomic<bool>& stop;
        ~Joiner() {
            if (std::uncaught_exceptions() > 0) stop = true;
            for (std::thread& t : threads)
                if (t.joinable()) t.join();
        }
    } joiner{threads, stop};
    for (unsigned k = 0; k < job.ranges; ++k)
        threads.emplace_back(run_range, std::cref(job), k, std::ref(*ranges[k]), std::ref(stop));

    auto tick = [&] {
        uint64_t n = 0;
        for (const auto& r : ranges) n += r->decimated;
        progress(n);
    };
    io::TriangleChunk chunk(job.options.output_chunk_triangles, io::Channels{});
    double weight = 1;
    if (job.seams_after_ranges)
        for (const auto& r : ranges) r->spool->wait_closed(stop, tick);
    for (unsigned k = 0; k < job.ranges && !stop; ++k) {
        // The first range borders no range before it: its output is read as it comes.
        const Piece first_range[] = {Piece::kInterior, Piece::kFirstSeam, Piece::kLastSeam};
        const Piece later_range[] = {Piece::kFirstSeam, Piece::kInterior, Piece::kLastSeam};
        for (const Piece piece : k == 0 ? first_range : later_range)
            while (ranges[k]->spool->next(piece, chunk, weight, stop, tick)) {
                seams->push(chunk, weight, emit);
                tick();
            }
    }
    for (std::thread& t : threads) t.join();
    for (const auto& r : ranges)
        if (std::exception_ptr error = r->spool->error()) std::rethrow_exception(error);

    RangesResult result;
    result.ratio = job.options.ratio;
    for (const auto& r : ranges)
        if (r->forced) {
            result.stopped_at_forced_write = true;
            result.forced_write_at = r->start + r->forced_at;
            return result;
        }
    uint64_t triangles_in = 0;
    for (const auto& r : ranges) triangles_in += r->stats.triangles_in;
    seams->finish_at(
        job.target ? *job.target : decimate::StreamDecimator::expected_output(job.options.ratio, triangles_in), emit);

    const decimate::Stats& s = seams->stats();
    decimate::Stats& t = result.stats;
    t = s;
    t.triangles_in = 0;
    t.buffer_capacity = job.options.buffer_triangles;
    t.peak_buffer_triangles = t.peak_vertices = 0;
    t.forced_writes = t.premature_writes = t.degenerate_passed = t.nonmanifold_edges = 0;
    t.vertices_merged = t.vertices_finalized_by_sweep = t.sort_violations = 0;
    t.sweep_direction = ranges.front()->stats.sweep_direction;
    for (const auto& r : ranges) {
        const decimate::Stats& x = r->stats;
        t.triangles_in += x.triangles_in;
        t.peak_buffer_triangles = std::max(t.peak_buffer_triangles, x.peak_buffer_triangles);
        t.peak_vertices = std::max(t.peak_vertices, x.peak_vertices);
        t.collapses += x.collapses;
        t.forced_writes += x.forced_writes;
        t.premature_writes += x.premature_writes;
        t.degenerate_passed += x.degenerate_passed;
        t.weld_dropped += x.weld_dropped;
        t.nonmanifold_edges += x.nonmanifold_edges;
        t.vertices_merged += x.vertices_merged;
        t.vertices_finalized_by_sweep += x.vertices_finalized_by_sweep;
        t.sort_violations += x.sort_violations;
        t.orphans_evicted += x.orphans_evicted;
        t.vertices_moved += x.vertices_moved;
    }
    result.seams = s;
    const Range& last = *ranges.back();
    result.count = last.count;
    result.dropped = last.dropped;
    result.end_header = last.end_header;
    return result;
}

}  // namespace meshstream::tools
