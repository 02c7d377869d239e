// Parallel decimation in ranges with a seam pass: see ranges.hpp.
#include "engine/ranges.hpp"

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
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace meshstream::engine {

namespace {

// One range's output on its way to the seam pass: its triangles' records (io::TriangleRecords) in a
// temporary file, and for each chunk its piece, triangle count and the input triangles each of
// them stands for. Appended to by the range's thread (or the thread receiving a remote range),
// read by the seam pass's.
class RangeSpool final : public RangeSink {
public:
    RangeSpool(const std::string& tmpdir, const io::Channels& channels)
        : file_(tmpdir, "meshstream-range"), records_(channels) {}

    void append(const io::TriangleChunk& chunk, double weight, Piece piece) override {
        encoded_.clear();
        records_.encode(chunk, encoded_);
        file_.write(encoded_.data(), encoded_.size());
        file_.flush();  // the seam pass reads the file directly (pread), not this object's buffer
        const std::lock_guard lock(mutex_);
        chunks_.push_back({written_, chunk.size(), weight, piece});
        written_ += encoded_.size();
        changed_.notify_all();
    }
    void progress(uint64_t decimated) override { decimated_ = decimated; }
    void close(const RangeOutcome& outcome, std::exception_ptr error) override {
        const std::lock_guard lock(mutex_);
        done_ = true;
        outcome_ = outcome;
        error_ = std::move(error);
        changed_.notify_all();
    }
    uint64_t decimated() const { return decimated_; }
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
        const size_t bytes = c.triangles * records_.bytes();
        read_.resize(bytes);
        char* dst = read_.data();
        for (size_t got = 0; got < bytes;) {
            const ssize_t r = ::pread(file_.fd(), dst + got, bytes - got, off_t(c.offset + got));
            if (r < 0 && errno == EINTR) continue;
            if (r <= 0)
                throw io::Error(file_.path(), std::string("cannot read a range's spooled output back: ") +
                                                  (r < 0 ? std::strerror(errno) : "file shorter than written"));
            got += size_t(r);
        }
        records_.decode(read_.data(), c.triangles, chunk);
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
    // Once the range is closed: its exception, if it failed, and how it ended.
    std::exception_ptr error() {
        const std::lock_guard lock(mutex_);
        return error_;
    }
    RangeOutcome outcome() {
        const std::lock_guard lock(mutex_);
        return outcome_;
    }

private:
    struct Chunk {
        uint64_t offset = 0;
        size_t triangles = 0;
        double weight = 1;
        Piece piece = Piece::kInterior;
    };
    io::TempFile file_;
    io::TriangleRecords records_;
    std::vector<char> encoded_;  // the range's thread's
    std::vector<char> read_;     // the seam pass's
    std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<Chunk> chunks_;
    uint64_t written_ = 0;
    bool done_ = false;
    RangeOutcome outcome_;
    std::exception_ptr error_;
    std::atomic<uint64_t> decimated_{0};
    size_t cursor_[3] = {0, 0, 0};  // the seam pass's: the next chunk of each piece to look at
};

// One range and, for the last one, what its read loop found.
struct Range {
    std::unique_ptr<RangeSpool> spool;
    // The last range reads the whole input: its read loop's figures are the input's.
    io::InputCount count;
    DroppedTriangles dropped;
    io::MeshHeader end_header;
};

// Range k's triangles: [start, end) of the read loop's passed triangles.
std::pair<uint64_t, uint64_t> range_bounds(const RangesJob& job, unsigned k) {
    return {job.cut_triangles * k / job.ranges,
            k + 1 == job.ranges ? std::numeric_limits<uint64_t>::max() : job.cut_triangles * (k + 1) / job.ranges};
}

// run_range() with the last range's read loop figures kept.
void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop, Range* last);

}  // namespace

void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop) {
    run_range(job, k, sink, stop, nullptr);
}

namespace {

void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop, Range* last) {
    std::exception_ptr error;
    RangeOutcome outcome;
    uint64_t decimated = 0;  // triangles of the range pushed so far
    const auto [start, end] = range_bounds(job, k);
    try {
        io::TriangleInput in = job.open();
        decimate::Options options = job.options;
        options.part = decimate::Part::kRange;
        // The triangles before the range are read past (no format has to seek); on sorted input
        // their span along the axis tells the sweep which vertices an earlier range may share.
        const int axis = options.sorted_axis.value_or(-1);
        double span_lo = std::numeric_limits<double>::infinity(), span_hi = -span_lo;
        io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, job.channels);
        io::TriangleChunk part(io::TriangleChunk::kDefaultCapacity, job.channels);
        uint64_t passed = 0;  // passed triangles of the read loop seen so far
        size_t first = 0;     // the range begins at this triangle of `chunk`
        bool straddles = false;
        while (passed < start && !stop) {
            if (!in.next(chunk)) break;
            const size_t skip = size_t(std::min<uint64_t>(chunk.size(), start - passed));
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
        const decimate::Emit interior = [&](const io::TriangleChunk& c) { sink.append(c, weight, Piece::kInterior); };
        const decimate::Emit first_seam = [&](const io::TriangleChunk& c) { sink.append(c, 1.0, Piece::kFirstSeam); };
        const decimate::Emit last_seam = [&](const io::TriangleChunk& c) { sink.append(c, 1.0, Piece::kLastSeam); };
        // Pushes `c`; false at a forced write that stops the job.
        auto push = [&](const io::TriangleChunk& c) {
            decimator->push(c, interior);
            decimated += c.size();
            sink.progress(decimated);
            if (!job.stop_at_forced_write || decimator->stats().forced_writes == 0) return true;
            outcome.forced_at = decimated;
            outcome.forced = true;
            stop = true;
            return false;
        };
        bool going = !stop;
        if (straddles && going) {
            part.clear();
            for (size_t i = first; i < chunk.size() && passed < end; ++i, ++passed) part.push_copy(chunk, i);
            going = push(part);
        }
        while (going && passed < end && !stop && in.next(chunk)) {
            if (chunk.size() <= end - passed) {
                passed += chunk.size();
                going = push(chunk);
            } else {
                part.clear();
                for (size_t i = 0; passed < end; ++i, ++passed) part.push_copy(chunk, i);
                going = push(part);
            }
        }
        if (going && !stop) {
            decimator->finish_range(interior, first_seam, last_seam);
            outcome.stats = decimator->stats();
            if (last) {
                last->count = in.count();
                last->dropped = dropped_triangles(in);
                last->end_header = in.header();
            }
        }
    } catch (...) {
        // The first bad input in the file's order: every range reads the file from its start,
        // so each range that fails fails at the first error before its end.
        error = std::current_exception();
        stop = true;
    }
    sink.close(outcome, error);
}

}  // namespace

unsigned range_count(unsigned threads, uint64_t triangles, size_t buffer) {
    if (buffer < kMinRangeBuffer) return 1;
    return unsigned(std::max<uint64_t>(1, std::min<uint64_t>(threads, triangles / buffer)));
}

RangesResult decimate_in_ranges(const RangesJob& job, const decimate::Emit& emit, ProgressSink& progress) {
    if (job.remote_ranges >= job.ranges || (job.remote_ranges > 0 && !job.receive_remote))
        throw std::logic_error("decimate_in_ranges: the last range runs here, and remote ranges need receive_remote");
    std::vector<std::unique_ptr<Range>> ranges;
    for (unsigned k = 0; k < job.ranges; ++k) {
        auto range = std::make_unique<Range>();
        range->spool = std::make_unique<RangeSpool>(job.tmpdir, job.channels);
        ranges.push_back(std::move(range));
    }
    // The seam pass: the ranges' outputs carry no sort order, and their welded positions meet
    // again on the same weld grid.
    decimate::Options seam_options = job.options;
    seam_options.part = decimate::Part::kSeams;
    seam_options.buffer_triangles = decimate::seam_pass_buffer(job.options.buffer_triangles);
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
    if (job.remote_ranges > 0) {
        std::vector<RangeSink*> sinks;
        for (unsigned k = 0; k < job.remote_ranges; ++k) sinks.push_back(ranges[k]->spool.get());
        threads.emplace_back([&job, &stop, sinks = std::move(sinks)] {
            try {
                job.receive_remote(sinks, stop);
            } catch (...) {
                // The remote ranges' sinks that are still open are closed with the failure.
                const std::exception_ptr error = std::current_exception();
                stop = true;
                for (RangeSink* sink : sinks) sink->close({}, error);
            }
        });
    }
    for (unsigned k = job.remote_ranges; k < job.ranges; ++k) {
        Range* last = k + 1 == job.ranges ? ranges[k].get() : nullptr;
        threads.emplace_back(
            [&job, k, &stop, last, sink = ranges[k]->spool.get()] { run_range(job, k, *sink, stop, last); });
    }

    bool cancelled = false;
    auto tick = [&] {
        uint64_t n = 0;
        for (const auto& r : ranges) n += r->spool->decimated();
        progress.update(n);
        if (progress.cancelled()) cancelled = stop = true;
    };
    io::TriangleChunk chunk(job.options.output_chunk_triangles, job.channels);
    double weight = 1;
    if (job.seams_after_ranges)
        for (const auto& r : ranges) r->spool->wait_closed(stop, tick);
    for (unsigned k = 0; k < job.ranges && !stop; ++k) {
        for (const Piece piece : {Piece::kInterior, Piece::kFirstSeam, Piece::kLastSeam})
            while (ranges[k]->spool->next(piece, chunk, weight, stop, tick)) {
                seams->push(chunk, weight, emit);
                tick();
            }
    }
    for (std::thread& t : threads) t.join();
    if (cancelled) throw Cancelled();
    for (const auto& r : ranges)
        if (std::exception_ptr error = r->spool->error()) std::rethrow_exception(error);

    std::vector<RangeOutcome> outcomes;
    for (const auto& r : ranges) outcomes.push_back(r->spool->outcome());
    RangesResult result;
    result.ratio = job.options.ratio;
    for (unsigned k = 0; k < job.ranges; ++k)
        if (outcomes[k].forced) {
            result.stopped_at_forced_write = true;
            result.forced_write_at = range_bounds(job, k).first + outcomes[k].forced_at;
            return result;
        }
    uint64_t triangles_in = 0;
    for (const RangeOutcome& o : outcomes) triangles_in += o.stats.triangles_in;
    seams->finish_at(
        job.target ? *job.target : decimate::StreamDecimator::expected_output(job.options.ratio, triangles_in), emit);

    // The ranges' and the seam pass's, summed as the summary shows them (decimate/stats.hpp).
    std::vector<decimate::Stats> range_stats;
    for (const RangeOutcome& o : outcomes) range_stats.push_back(o.stats);
    result.stats = decimate::combine_ranges(seams->stats(), range_stats, job.options.buffer_triangles);
    result.seams = seams->stats();
    const Range& last = *ranges.back();
    result.count = last.count;
    result.dropped = last.dropped;
    result.end_header = last.end_header;
    return result;
}

}  // namespace meshstream::engine
