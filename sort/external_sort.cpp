// External merge sort of triangle records (see external_sort.hpp for the contract). Runs live
// as consecutive segments of one temporary file; a merge pass reads them through per-run
// buffers that share the budget, picks the smallest (key, run number) with a loser tree, and
// either fills output chunks (final pass) or appends to the next temporary file.
#include "sort/external_sort.hpp"

#include "io/error.hpp"
#include "sort/radix.hpp"

#include <fcntl.h>
#include <sys/mman.h>

#include <algorithm>
#include <cassert>
#include <cstring>

namespace meshstream::sort {
namespace {

constexpr size_t kStagingBytes = size_t{1} << 20;       // >= TempFile's buffer: writes bypass it
constexpr uint64_t kMinReadBytes = uint64_t{64} << 10;  // smallest per-run read buffer
constexpr uint64_t kMaxReadBytes = uint64_t{16} << 20;  // larger reads gain nothing
constexpr uint64_t kMinRunTriangles = 1024;
constexpr uint64_t kPageBytes = 4096;  // hole punching frees whole pages only
// Gathering records in key order is a random walk over the run buffer: prefetching the record
// this many items ahead hides most of the cache and TLB misses (2-3x faster gathers).
constexpr size_t kPrefetchDistance = 16;

// Asks for transparent huge pages on the run buffers (Linux, THP in "madvise" mode): a
// gather in key order touches a new page for almost every record, and with 4 KiB pages a
// 500 MB run costs ~130 000 page faults and a TLB miss per record. Advisory: ignored where
// unsupported. RSS still grows only as the buffer fills (in 2 MiB steps).
void advise_huge_pages(void* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
    constexpr uintptr_t kHuge = uintptr_t{2} << 20;
    const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
    if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)p, (void)bytes;
#endif
}

// Prefetches the record of the item `ahead` positions further in `sorted` (both cache lines
// a record may straddle).
inline void prefetch_record(const std::byte* records, size_t record_bytes, std::span<const uint64_t> sorted, size_t i) {
    if (i + kPrefetchDistance < sorted.size()) {
        const std::byte* r = records + (sorted[i + kPrefetchDistance] & 0xFFFFFFFFu) * record_bytes;
        __builtin_prefetch(r);
        __builtin_prefetch(r + record_bytes - 1);
    }
}

}  // namespace

// One run being merged: a window of its records in a read buffer.
struct ExternalSorter::Cursor {
    uint64_t start_offset = 0;  // first byte of the run in the file
    uint64_t next_offset = 0;   // first unread byte of the run in the file
    uint64_t end_offset = 0;    // end of the run in the file
    std::byte* buf = nullptr;
    size_t capacity = 0;  // bytes, a multiple of the record size
    size_t pos = 0, len = 0;
    uint64_t block_offset = 0;  // file range of the buffered block, released once consumed
    uint32_t run = 0;           // position among the merged runs: breaks key ties (stability)
};

class ExternalSorter::Merger {
public:
    Merger(ExternalSorter& owner, io::TempFile& file, std::span<const Segment> segments, uint64_t buffer_budget)
        : owner_(owner), file_(file) {
        const size_t rb = owner.record_bytes_;
        const size_t k = std::max<size_t>(1, segments.size());
        // At least 64 KiB even past a tiny budget (fan-in 2, so 128 KiB at most): smaller reads
        // cost a system call per few records, and releasing less than a page frees nothing.
        uint64_t per_run = std::clamp(buffer_budget / k, kMinReadBytes, kMaxReadBytes);
        size_t capacity = std::max<size_t>(1, per_run / rb) * rb;
        storage_.reset(new std::byte[capacity * segments.size()]);
        cursors_.resize(k);
        order_.assign(k, kExhausted);
        for (size_t i = 0; i < segments.size(); ++i) {
            Cursor& c = cursors_[i];
            c.start_offset = c.next_offset = segments[i].offset;
            c.end_offset = segments[i].offset + segments[i].count * rb;
            c.buf = storage_.get() + i * capacity;
            c.capacity = capacity;
            c.run = static_cast<uint32_t>(i);
            if (refill(c)) order_[i] = rank(c);
        }
        // Loser tree (Knuth, TAOCP vol. 3, §5.4.1): leaf i sits at node k + i, node p's children
        // are 2p and 2p + 1; each inner node keeps the loser of its match, tree_[0] the winner.
        tree_.assign(k, 0);
        std::vector<uint32_t> winner(2 * k);
        for (size_t i = 0; i < k; ++i) winner[k + i] = static_cast<uint32_t>(i);
        for (size_t p = k - 1; p >= 1; --p) {
            uint32_t a = winner[2 * p], b = winner[2 * p + 1];
            const bool a_wins = order_[a] < order_[b];
            winner[p] = a_wins ? a : b;
            tree_[p] = a_wins ? b : a;
        }
        tree_[0] = winner[1];
    }

    // The smallest remaining record (owner's record size), or null when all runs are consumed.
    const std::byte* top() const {
        const uint32_t w = tree_[0];
        if (order_[w] == kExhausted) return nullptr;
        const Cursor& c = cursors_[w];
        return c.buf + c.pos;
    }

    // Consumes top(): advances its run and replays the matches on the way to the root (one
    // comparison per level, log2(k) in all, against a binary heap's ~2·log2(k)).
    void pop() {
        uint32_t w = tree_[0];
        Cursor& c = cursors_[w];
        c.pos += owner_.record_bytes_;
        order_[w] = (c.pos < c.len || refill(c)) ? rank(c) : kExhausted;
        const size_t k = cursors_.size();
        for (size_t p = (w + k) / 2; p >= 1; p /= 2) {
            if (order_[tree_[p]] < order_[w]) std::swap(tree_[p], w);
        }
        tree_[0] = w;
    }

private:
    // A cursor's place in the merge order: its current key, ties broken by run number
    // (stability). All real ranks are below kExhausted.
    static constexpr uint64_t kExhausted = ~uint64_t{0};
    uint64_t rank(const Cursor& c) const { return uint64_t{key_at(c)} << 32 | c.run; }

    uint32_t key_at(const Cursor& c) const {
        float xyz[9];
        std::memcpy(xyz, c.buf + c.pos, sizeof xyz);  // records are not float-aligned with colours
        return owner_.key_of(xyz);
    }

    // Reads the cursor's next block; false when its run is exhausted. Releases the consumed one.
    bool refill(Cursor& c) {
        if (c.len > 0) {
            // From the page holding the block's first byte, whose earlier bytes were this run's
            // previous block (a page that begins before the run may hold another run's data).
            const uint64_t first_page = (c.start_offset + kPageBytes - 1) / kPageBytes * kPageBytes;
            const uint64_t from = std::max(c.block_offset / kPageBytes * kPageBytes, first_page);
            owner_.release_temp_range(file_, from, c.block_offset + c.len, c.len);
        }
        c.pos = c.len = 0;
        if (c.next_offset >= c.end_offset) return false;
        size_t n = static_cast<size_t>(std::min<uint64_t>(c.capacity, c.end_offset - c.next_offset));
        file_.read_at(c.next_offset, c.buf, n);
        c.block_offset = c.next_offset;
        c.next_offset += n;
        c.len = n;
        return true;
    }

    ExternalSorter& owner_;
    io::TempFile& file_;
    std::unique_ptr<std::byte[]> storage_;
    std::vector<Cursor> cursors_;
    std::vector<uint64_t> order_;  // rank of each cursor's current record, kExhausted when done
    std::vector<uint32_t> tree_;   // loser tree over cursor indices; [0] = the winner
};

size_t ExternalSorter::record_bytes_for(const io::Channels& channels) {
    return io::TriangleRecords(channels).bytes();
}

uint64_t ExternalSorter::run_capacity_for(uint64_t memory_budget_bytes, size_t record_bytes) {
    // Per triangle: its record plus two 8-byte (key, position) items for the radix sort.
    uint64_t n = memory_budget_bytes / (record_bytes + 2 * sizeof(uint64_t));
    return std::clamp<uint64_t>(n, kMinRunTriangles, uint64_t{0xFFFFFFFF});
}

ExternalSorter::ExternalSorter(SorterOptions options)
    : options_(std::move(options)),
      record_bytes_(record_bytes_for(options_.channels)),
      codec_(options_.channels) {
    assert(options_.axis >= 0 && options_.axis <= 2);
    stats_.record_bytes = record_bytes_;
    stats_.run_capacity = run_capacity_for(options_.memory_budget_bytes, record_bytes_);
}

ExternalSorter::~ExternalSorter() = default;

uint32_t ExternalSorter::key_of(const float* xyz) const {
    return options_.key ? options_.key(xyz) : triangle_key(xyz, options_.axis);
}

void ExternalSorter::add(const io::TriangleChunk& chunk) {
    keys_.resize(chunk.size());
    auto xyz = chunk.xyz();
    for (size_t i = 0; i < chunk.size(); ++i) keys_[i] = key_of(&xyz[9 * i]);
    add(chunk, keys_);
}

void ExternalSorter::add(const io::TriangleChunk& chunk, std::span<const uint32_t> keys) {
    assert(!input_done_);
    assert(chunk.channels() == options_.channels);
    assert(keys.size() == chunk.size());
    const uint64_t capacity = stats_.run_capacity;
    if (!records_) {
        // Uninitialised: pages are touched (and count toward RSS) only as the run fills.
        records_.reset(new std::byte[capacity * record_bytes_]);
        items_.reset(new uint64_t[capacity]);
        advise_huge_pages(records_.get(), capacity * record_bytes_);
        advise_huge_pages(items_.get(), capacity * sizeof(uint64_t));
    }
    for (size_t i = 0; i < chunk.size(); ++i) {
        if (run_size_ == capacity) spill_run();
        codec_.encode(chunk, i, records_.get() + run_size_ * record_bytes_);
        items_[run_size_] = uint64_t{keys[i]} << 32 | run_size_;
        ++run_size_;
    }
    stats_.triangles += chunk.size();
}

void ExternalSorter::sort_run() {
    if (run_size_ == 0) {
        sorted_ = {};
        return;
    }
    if (!scratch_) {
        scratch_.reset(new uint64_t[stats_.run_capacity]);
        advise_huge_pages(scratch_.get(), stats_.run_capacity * sizeof(uint64_t));
    }
    sorted_ = radix_sort_by_key({items_.get(), run_size_}, {scratch_.get(), run_size_});
}

void ExternalSorter::write_temp(io::TempFile& file, const void* data, size_t n) {
    try {
        file.write(data, n);
        // A partial block would wait in the file's buffer until the merge reads, and a full
        // disk would then be reported without the advice below.
        file.flush();
    } catch (const io::Error& e) {
        throw io::Error(e.file(), e.byte_offset(), 0,
                        e.raw_message() + " (temporary file of meshstream sort; " + io::mention(io::Setting::kTmpdir) +
                            " picks another directory)");
    }
    stats_.temp_bytes_written += n;
    live_temp_bytes_ += n;
    stats_.peak_temp_bytes = std::max(stats_.peak_temp_bytes, live_temp_bytes_);
}

void ExternalSorter::release_temp_range(io::TempFile& file, uint64_t begin, uint64_t end, uint64_t consumed) {
#ifdef FALLOC_FL_PUNCH_HOLE
    // Consumed run data is never read again: give its blocks back so a merge pass needs about
    // one copy of the data on disk, not two. File systems without hole punching just keep it.
    if (begin >= end || ::fallocate(file.fd(), FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(begin),
                                    static_cast<off_t>(end - begin)) == 0)
        live_temp_bytes_ -= std::min(live_temp_bytes_, consumed);
#else
    (void)file, (void)begin, (void)end, (void)consumed;
#endif
}

void ExternalSorter::spill_run() {
    sort_run();
    if (!runs_file_) runs_file_ = std::make_unique<io::TempFile>(options_.tmpdir, "meshstream-sort");
    if (staging_.empty()) staging_.resize(kStagingBytes);
    const uint64_t start = runs_file_->size();
    size_t fill = 0;
    for (size_t i = 0; i < sorted_.size(); ++i) {
        if (fill + record_bytes_ > staging_.size()) {
            write_temp(*runs_file_, staging_.data(), fill);
            fill = 0;
        }
        prefetch_record(records_.get(), record_bytes_, sorted_, i);
        const uint64_t item = sorted_[i];
        std::memcpy(staging_.data() + fill, records_.get() + (item & 0xFFFFFFFFu) * record_bytes_, record_bytes_);
        fill += record_bytes_;
    }
    if (fill) write_temp(*runs_file_, staging_.data(), fill);
    segments_.push_back({start, run_size_});
    ++stats_.runs;
    run_size_ = 0;
}

void ExternalSorter::finish_input() {
    assert(!input_done_);
    input_done_ = true;
    if (segments_.empty()) {
        sort_run();  // everything fits in one run: no disk
        return;
    }
    if (run_size_ > 0) spill_run();
    records_.reset();
    items_.reset();
    scratch_.reset();
    sorted_ = {};

    const uint64_t budget = options_.memory_budget_bytes;
    const size_t fan_in = static_cast<size_t>(std::max<uint64_t>(2, budget / kMinReadBytes));
    int pass_count = 1;
    for (size_t r = segments_.size(); r > fan_in; r = (r + fan_in - 1) / fan_in) ++pass_count;
    for (int pass = 1; pass < pass_count; ++pass) merge_pass(pass, pass_count, fan_in);
    stats_.merge_passes = pass_count;
    start_final_merge();
}

void ExternalSorter::merge_pass(int pass, int pass_count, size_t fan_in) {
    auto out = std::make_unique<io::TempFile>(options_.tmpdir, "meshstream-sort");
    std::vector<Segment> merged;
    // Spread the runs evenly over the groups, consecutive runs together (stability).
    const size_t groups = (segments_.size() + fan_in - 1) / fan_in;
    const size_t base = segments_.size() / groups, extra = segments_.size() % groups;
    size_t first = 0;
    uint64_t done = 0;
    for (size_t g = 0; g < groups; ++g) {
        size_t count = base + (g < extra ? 1 : 0);
        std::span<const Segment> group(segments_.data() + first, count);
        first += count;
        Merger merger(*this, *runs_file_, group, options_.memory_budget_bytes);
        const uint64_t start = out->size();
        uint64_t triangles = 0;
        size_t fill = 0;
        while (const std::byte* rec = merger.top()) {
            if (fill + record_bytes_ > staging_.size()) {
                write_temp(*out, staging_.data(), fill);
                fill = 0;
                if (options_.on_merge_progress) options_.on_merge_progress(pass, pass_count, done + triangles);
            }
            std::memcpy(staging_.data() + fill, rec, record_bytes_);
            fill += record_bytes_;
            ++triangles;
            merger.pop();
        }
        if (fill) write_temp(*out, staging_.data(), fill);
        merged.push_back({start, triangles});
        done += triangles;
    }
    // The old file's unreleased bytes go away with it.
    uint64_t old_live = live_temp_bytes_ - out->size();
    live_temp_bytes_ -= std::min(live_temp_bytes_, old_live);
    runs_file_ = std::move(out);
    segments_ = std::move(merged);
    if (options_.on_merge_progress) options_.on_merge_progress(pass, pass_count, done);
}

void ExternalSorter::start_final_merge() {
    final_ = std::make_unique<Merger>(*this, *runs_file_, segments_, options_.memory_budget_bytes);
}

bool ExternalSorter::next(io::TriangleChunk& chunk) {
    assert(input_done_);
    assert(chunk.channels() == options_.channels);
    chunk.clear();
    if (!final_) {
        // In-memory result.
        while (!chunk.full() && emit_pos_ < sorted_.size()) {
            prefetch_record(records_.get(), record_bytes_, sorted_, emit_pos_);
            uint64_t item = sorted_[emit_pos_++];
            codec_.decode(records_.get() + (item & 0xFFFFFFFFu) * record_bytes_, chunk);
        }
        if (emit_pos_ == sorted_.size() && records_ && chunk.empty()) {
            records_.reset();
            items_.reset();
            scratch_.reset();
            sorted_ = {};
        }
        return !chunk.empty();
    }
    while (!chunk.full()) {
        const std::byte* rec = final_->top();
        if (!rec) break;
        codec_.decode(rec, chunk);
        final_->pop();
    }
    if (chunk.empty()) {
        final_.reset();
        runs_file_.reset();  // removes the file as soon as the output is complete
        live_temp_bytes_ = 0;
        segments_.clear();
        final_ = nullptr;
        emit_pos_ = 0;
        sorted_ = {};
        return false;
    }
    return true;
}

}  // namespace meshstream::sort
