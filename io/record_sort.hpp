// An external merge sort of fixed-size records in bounded memory, for the indexed formats'
// out-of-core welding (io/weld.cpp) and `info --topology`. Records are buffered up to a byte
// budget, sorted with std::sort and written as runs into one io::TempFile; reading merges the
// runs with a heap, each run read through its own pread block. A sort that never fills its
// buffer stays in memory. Classic replacement-free run formation (Knuth vol. 3, §5.4.1 without
// replacement selection): one write and one read of the data when it spills.
//
// Memory: the buffer (<= budget_bytes) while pushing; while merging, one block per run
// (merge_budget_bytes / runs, at least 16 KiB). When more runs than merge_budget / 16 KiB
// remain, groups of that many are first merged into longer runs in a new temporary file
// (one more write and read of the data per level, and twice the data on disk until the level
// ends and the old file goes), so the blocks stay within the merge budget: a single level
// covers budget × merge_budget / 16 KiB bytes of records (64 MiB
// each: 256 GiB).
#pragma once

#include "io/byte_stream.hpp"

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <memory>
#include <queue>
#include <string>
#include <type_traits>
#include <vector>

namespace meshstream::io {

template <class T, class Less>
class RecordSorter {
    static_assert(std::is_trivially_copyable_v<T>, "records are written to disk as bytes");

public:
    // `budget_bytes` bounds the run buffer; `tmpdir` (empty: $TMPDIR or /tmp) holds the runs.
    RecordSorter(uint64_t budget_bytes, std::string tmpdir, Less less = {}) : tmpdir_(std::move(tmpdir)), less_(less) {
        capacity_ = static_cast<size_t>(std::max<uint64_t>(budget_bytes / sizeof(T), 1024));
    }
    RecordSorter(const RecordSorter&) = delete;  // the heap points back at this object
    RecordSorter& operator=(const RecordSorter&) = delete;

    // Adds a record. Precondition: finish_input() not called yet. Throws io::Error (disk).
    void push(const T& record) {
        assert(!reading_);
        if (buffer_.size() == capacity_) spill();
        if (buffer_.capacity() == 0) buffer_.reserve(capacity_);
        buffer_.push_back(record);
        ++count_;
    }

    // Ends input; next() then yields all records in `less` order. Merge blocks share
    // `merge_budget_bytes`.
    void finish_input(uint64_t merge_budget_bytes) {
        assert(!reading_);
        reading_ = true;
        if (runs_.empty()) {  // everything fit: sort in memory
            std::sort(buffer_.begin(), buffer_.end(), less_);
            return;
        }
        if (!buffer_.empty()) spill();
        std::vector<T>().swap(buffer_);
        const size_t fan_in = static_cast<size_t>(std::max<uint64_t>(merge_budget_bytes / min_block_bytes(), 2));
        while (runs_.size() > fan_in) merge_level(fan_in, merge_budget_bytes);
        start_merge(0, runs_.size(), merge_budget_bytes);
    }

    // Pulls the next record in order; false when all have been read.
    bool next(T& out) {
        assert(reading_);
        if (runs_.empty()) {
            if (memory_pos_ == buffer_.size()) return false;
            out = buffer_[memory_pos_++];
            return true;
        }
        if (heap_.empty()) return false;
        size_t r = heap_.top();
        heap_.pop();
        Run& run = runs_[r];
        out = run.block[run.at++];
        if (run.at == run.filled) refill(r);
        if (run.at < run.filled) heap_.push(r);
        return true;
    }

    uint64_t size() const { return count_; }
    // Bytes of the merge's read blocks: within finish_input's merge budget unless that holds
    // fewer than two blocks of 16 KiB.
    uint64_t merge_block_bytes() const {
        uint64_t bytes = 0;
        for (const Run& run : runs_) bytes += run.block.capacity() * sizeof(T);
        return bytes;
    }
    // True when records went to disk.
    bool spilled() const { return !runs_.empty(); }

private:
    struct Run {
        uint64_t next_record = 0, end_record = 0;  // in records, within the temp file
        std::vector<T> block;
        size_t at = 0, filled = 0;
    };
    struct HeapLess {
        const RecordSorter* self;
        bool operator()(size_t a, size_t b) const {  // priority_queue is a max-heap: invert
            const Run& ra = self->runs_[a];
            const Run& rb = self->runs_[b];
            return self->less_(rb.block[rb.at], ra.block[ra.at]);
        }
    };

    void spill() {
        if (!file_) file_ = std::make_unique<TempFile>(tmpdir_, "meshstream-sort");
        std::sort(buffer_.begin(), buffer_.end(), less_);
        Run run;
        run.next_record = written_;
        file_->write(buffer_.data(), buffer_.size() * sizeof(T));
        written_ += buffer_.size();
        run.end_record = written_;
        runs_.push_back(std::move(run));
        buffer_.clear();
    }

    static constexpr uint64_t kMinBlockBytes = 16 * 1024;
    static constexpr uint64_t min_block_bytes() { return (kMinBlockBytes / sizeof(T) + 1) * sizeof(T); }

    // Gives runs [first, last) a block each from the merge budget and puts them on the heap.
    void start_merge(size_t first, size_t last, uint64_t merge_budget_bytes) {
        const size_t block = static_cast<size_t>(
            std::max<uint64_t>(merge_budget_bytes / (last - first) / sizeof(T), kMinBlockBytes / sizeof(T) + 1));
        for (size_t r = first; r < last; ++r) {
            runs_[r].block.resize(block);
            refill(r);
            if (runs_[r].at < runs_[r].filled) heap_.push(r);
        }
    }

    // One intermediate merge level: every `fan_in` consecutive runs become one run of a new
    // temporary file, which then replaces the old one.
    void merge_level(size_t fan_in, uint64_t merge_budget_bytes) {
        auto out = std::make_unique<TempFile>(tmpdir_, "meshstream-sort");
        std::vector<Run> merged;
        std::vector<T> staging;
        staging.reserve(static_cast<size_t>(kMinBlockBytes / sizeof(T) + 1));
        uint64_t written = 0;
        for (size_t first = 0; first < runs_.size(); first += fan_in) {
            const size_t last = std::min(runs_.size(), first + fan_in);
            Run run;
            run.next_record = written;
            start_merge(first, last, merge_budget_bytes);
            while (!heap_.empty()) {
                const size_t r = heap_.top();
                heap_.pop();
                Run& from = runs_[r];
                staging.push_back(from.block[from.at++]);
                if (from.at == from.filled) refill(r);
                if (from.at < from.filled) heap_.push(r);
                if (staging.size() == staging.capacity()) {
                    out->write(staging.data(), staging.size() * sizeof(T));
                    written += staging.size();
                    staging.clear();
                }
            }
            out->write(staging.data(), staging.size() * sizeof(T));
            written += staging.size();
            staging.clear();
            for (size_t r = first; r < last; ++r) std::vector<T>().swap(runs_[r].block);
            run.end_record = written;
            merged.push_back(std::move(run));
        }
        file_ = std::move(out);
        runs_ = std::move(merged);
        written_ = written;
    }

    void refill(size_t r) {
        Run& run = runs_[r];
        size_t n = static_cast<size_t>(std::min<uint64_t>(run.block.size(), run.end_record - run.next_record));
        if (n > 0) file_->read_at(run.next_record * sizeof(T), run.block.data(), n * sizeof(T));
        run.next_record += n;
        run.at = 0;
        run.filled = n;
    }

    std::string tmpdir_;
    Less less_;
    size_t capacity_;
    std::vector<T> buffer_;
    size_t memory_pos_ = 0;
    uint64_t count_ = 0, written_ = 0;
    bool reading_ = false;
    std::unique_ptr<TempFile> file_;
    std::vector<Run> runs_;
    std::priority_queue<size_t, std::vector<size_t>, HeapLess> heap_{HeapLess{this}};
};

}  // namespace meshstream::io
