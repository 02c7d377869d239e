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
    // A range that reads from where it assumes its triangles start (RangeRun) holds its chunks
    // back from the seam pass until its start is confirmed, or drops them (reset) and starts
    // again.
    void hold() {
        const std::lock_guard lock(mutex_);
        confirmed_ = false;
    }
    void confirm() {
        const std::lock_guard lock(mutex_);
        confirmed_ = true;
        changed_.notify_all();
    }
    void reset() {
        const std::lock_guard lock(mutex_);
        chunks_.clear();  // their bytes stay in the file, unread
        for (size_t& i : cursor_) i = 0;
        decimated_ = 0;
    }
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
                if (stop) return false;
                if (confirmed_) {
                    while (i < chunks_.size() && chunks_[i].piece != piece) ++i;
                    if (i < chunks_.size()) break;
                }
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
    bool confirmed_ = true;
    RangeOutcome outcome_;
    std::exception_ptr error_;
    std::atomic<uint64_t> decimated_{0};
    size_t cursor_[3] = {0, 0, 0};  // the seam pass's: the next chunk of each piece to look at
};

// One range and, for the last one, what its read loop found.
struct Range {
    std::unique_ptr<RangeSpool> spool;
    io::InputCount count;
    DroppedTriangles dropped;
    io::MeshHeader end_header;
};

// What the ranges on threads of decimate_in_ranges share.
struct SharedCut {
    explicit SharedCut(unsigned ranges)
        : first_failed(ranges), first_drop(ranges), read_done(std::make_unique<std::atomic<bool>[]>(ranges)) {}
    // The lowest range that failed: a range stops once a range before it failed, and runs on
    // when one after it did, so that the error rethrown is the first in the file's order.
    std::atomic<unsigned> first_failed;
    // The lowest range but the last that read its own records (select_triangles) and met one
    // the read loop drops: the ranges after it start elsewhere than they assumed.
    std::atomic<unsigned> first_drop;
    std::unique_ptr<std::atomic<bool>[]> read_done;  // range k has read its last triangle
};

// How a range on a thread of decimate_in_ranges runs besides the job.
struct RangeRun {
    Range* last = nullptr;         // the last range: its read loop's figures
    RangeSpool* spool = nullptr;   // its sink
    SharedCut* shared = nullptr;   // null for a range run elsewhere
};

// Range k's triangles: [start, end) of the read loop's passed triangles.
std::pair<uint64_t, uint64_t> range_bounds(const RangesJob& job, unsigned k) {
    return {job.cut_triangles * k / job.ranges,
            k + 1 == job.ranges ? std::numeric_limits<uint64_t>::max() : job.cut_triangles * (k + 1) / job.ranges};
}

void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop, const RangeRun& run);

}  // namespace

void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop) {
    run_range(job, k, sink, stop, RangeRun{});
}

namespace {

void run_range(const RangesJob& job, unsigned k, RangeSink& sink, std::atomic<bool>& stop, const RangeRun& run) {
    std::exception_ptr error;
    RangeOutcome outcome;
    SharedCut* const shared = run.shared;
    const auto halted = [&] { return stop || (shared && shared->first_failed < k); };
    // A range of an unsorted binary STL on a thread here goes straight to the record where its
    // triangles start when none before it is dropped (the cut counts the triangles the read loop
    // passes on), and reads on from there; it confirms that assumption once the ranges before it
    // have read theirs, or, as soon as one of them met a dropped triangle, starts again reading
    // its way from the input's start. Any other range reads its way to its range.
    bool may_select = shared != nullptr && !job.options.sorted_axis;
    const bool is_last = k + 1 == job.ranges;
    for (;;) {
        outcome = {};
        bool again = false;
        uint64_t decimated = 0;  // triangles of the range pushed so far
        const auto [start, end] = range_bounds(job, k);
        try {
            io::TriangleInput in = job.open();
            decimate::Options options = job.options;
            options.part = decimate::Part::kRange;
            bool selected = false;
            if (may_select && in.count().promised && start <= *in.count().promised) {
                selected = in.select_triangles(start, *in.count().promised);
                if (selected && k > 0) run.spool->hold();
            }
            // A range assumed to start at its record starts again once a range before it dropped one.
            const auto misplaced = [&] { return selected && shared->first_drop < k; };
            // The triangles before the range are read past; on sorted input their span along the
            // axis tells the sweep which vertices an earlier range may share.
            const int axis = options.sorted_axis.value_or(-1);
            double span_lo = std::numeric_limits<double>::infinity(), span_hi = -span_lo;
            io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, job.channels);
            io::TriangleChunk part(io::TriangleChunk::kDefaultCapacity, job.channels);
            uint64_t passed = selected ? start : 0;  // passed triangles of the read loop seen so far
            size_t first = 0;                        // the range begins at this triangle of `chunk`
            bool straddles = false;
            while (passed < start && !halted()) {
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
            bool going = !halted();
            if (straddles && going) {
                part.clear();
                for (size_t i = first; i < chunk.size() && passed < end; ++i, ++passed) part.push_copy(chunk, i);
                going = push(part);
            }
            while (going && passed < end && !halted() && !misplaced() && in.next(chunk)) {
                if (selected && !is_last && in.count().dropped > 0) {
                    unsigned dropping = shared->first_drop;
                    while (k < dropping && !shared->first_drop.compare_exchange_weak(dropping, k)) {}
                }
                if (chunk.size() <= end - passed) {
                    passed += chunk.size();
                    going = push(chunk);
                } else {
                    part.clear();
                    for (size_t i = 0; passed < end; ++i, ++passed) part.push_copy(chunk, i);
                    going = push(part);
                }
            }
            if (shared) shared->read_done[k] = true;
            // Confirmed once every range before has read its triangles without a drop.
            for (unsigned j = 0; selected && j < k && going && !halted() && !misplaced(); ++j)
                while (!shared->read_done[j] && !halted() && !misplaced())
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));
            if (going && !halted() && misplaced()) {
                again = true;
            } else if (going && !halted()) {
                if (selected && k > 0) run.spool->confirm();
                decimator->finish_range(interior, first_seam, last_seam);
                outcome.stats = decimator->stats();
                if (selected) {
                    outcome.selected = true;
                    outcome.read = is_last ? in.count().read - start : end - start;
                    outcome.non_finite = in.non_finite();
                    outcome.degenerate = in.degenerate();
                }
                if (Range* last = run.last) {
                    last->count = in.count();
                    last->dropped = dropped_triangles(in);
                    last->end_header = in.header();
                }
            }
        } catch (...) {
            // The first bad input in the file's order: with `shared`, the ranges before this one
            // run on to their own errors, if any; without it (a range run elsewhere), every range
            // reads the file from its start, so each range that fails fails at the first error
            // before its end.
            error = std::current_exception();
            if (shared) {
                unsigned failed = shared->first_failed;
                while (k < failed && !shared->first_failed.compare_exchange_weak(failed, k)) {}
            } else {
                stop = true;
            }
        }
        if (!again) break;
        if (shared) shared->read_done[k] = false;
        run.spool->reset();
        run.spool->confirm();
        may_select = false;
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
    SharedCut shared(job.ranges);
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
        // The ranges read their own records only when every one runs here: ranges run elsewhere
        // cannot confirm where theirs start.
        const RangeRun run{k + 1 == job.ranges ? ranges[k].get() : nullptr, ranges[k]->spool.get(),
                           job.remote_ranges == 0 ? &shared : nullptr};
        threads.emplace_back(
            [&job, k, &stop, run, sink = ranges[k]->spool.get()] { run_range(job, k, *sink, stop, run); });
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
    for (unsigned k = 0; k < job.ranges && k <= shared.first_failed && !stop; ++k) {
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
    if (outcomes.back().selected) {
        // Each range read its own triangles: the input's figures are their sums.
        result.count.read = result.count.dropped = 0;
        result.dropped = {};
        for (const RangeOutcome& o : outcomes) {
            if (!o.selected) throw std::logic_error("decimate_in_ranges: ranges cut two ways");
            result.count.read += o.read;
            result.count.dropped += o.non_finite + o.degenerate;
            result.dropped.non_finite += o.non_finite;
            result.dropped.degenerate += o.degenerate;
        }
        result.dropped.read = result.count.read;
    }
    return result;
}

}  // namespace meshstream::engine
