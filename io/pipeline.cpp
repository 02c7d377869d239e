#include "io/pipeline.hpp"

#include <algorithm>
#include <cassert>
#include <utility>

namespace meshstream::io {

ChunkQueue::ChunkQueue(size_t slots, size_t capacity, const Channels& channels) {
    for (size_t i = 0; i < slots; ++i) {
        storage_.push_back(std::make_unique<PipelineSlot>(capacity, channels));
        free_.push_back(storage_.back().get());
    }
}

PipelineSlot* ChunkQueue::get_free() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !free_.empty() || stopped_ || error_; });
    if (stopped_) return nullptr;
    if (error_) std::rethrow_exception(error_);
    PipelineSlot* slot = free_.front();
    free_.pop_front();
    return slot;
}

PipelineSlot* ChunkQueue::get_full() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !full_.empty() || stopped_ || error_ || closed_; });
    if (stopped_) return nullptr;
    if (full_.empty()) {
        if (error_) std::rethrow_exception(error_);
        return nullptr;  // closed and drained
    }
    PipelineSlot* slot = full_.front();
    full_.pop_front();
    return slot;
}

void ChunkQueue::put_full(PipelineSlot* slot) {
    std::lock_guard lock(mutex_);
    full_.push_back(slot);
    changed_.notify_all();
}

void ChunkQueue::put_free(PipelineSlot* slot) {
    std::lock_guard lock(mutex_);
    free_.push_back(slot);
    changed_.notify_all();
}

void ChunkQueue::close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    changed_.notify_all();
}

void ChunkQueue::fail(std::exception_ptr error) {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = std::move(error);
    changed_.notify_all();
}

void ChunkQueue::stop() {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    changed_.notify_all();
}

void ChunkQueue::rethrow_failure() {
    std::lock_guard lock(mutex_);
    if (error_) std::rethrow_exception(error_);
}

ReadAhead::ReadAhead(TriangleInput& in, size_t capacity, const Channels& channels)
    : queue_(kPipelineChunks - 1, capacity, channels) {
    thread_ = std::thread([this, &in] {
        try {
            const bool has_source = in.has_source();
            while (PipelineSlot* slot = queue_.get_free()) {
                if (!in.next(slot->chunk)) {
                    queue_.put_free(slot);
                    break;
                }
                slot->count = in.count();
                slot->stored_offset = has_source ? in.source().stored_offset() : 0;
                queue_.put_full(slot);
            }
            queue_.close();
        } catch (...) {
            queue_.fail(std::current_exception());
        }
    });
}

ReadAhead::~ReadAhead() {
    queue_.stop();
    join();
}

void ReadAhead::join() {
    if (thread_.joinable()) thread_.join();
}

bool ReadAhead::next(TriangleChunk& chunk) {
    PipelineSlot* slot = nullptr;
    try {
        slot = queue_.get_full();
    } catch (...) {
        join();
        throw;
    }
    if (slot == nullptr) {
        join();
        chunk.clear();
        return false;
    }
    assert(slot->chunk.capacity() == chunk.capacity() && slot->chunk.channels() == chunk.channels());
    std::swap(slot->chunk, chunk);
    count_ = slot->count;
    stored_offset_ = slot->stored_offset;
    queue_.put_free(slot);
    return true;
}

namespace {
// What IndexedReadAhead::resolve reads the corners through: the source, or a split lookup.
struct SourceLookup {
    IndexedSource& source;
    void vertex(uint64_t i, float* xyz, std::byte* record) { source.vertex(i, xyz, record); }
    void prefetch(uint64_t i) { source.prefetch(i); }
};
}  // namespace

bool IndexedReadAhead::possible(TriangleInput& in, const Channels& channels) {
    return !channels.material && channels.face_scalars.empty() && in.reader().indexed() != nullptr;
}

IndexedReadAhead::IndexedReadAhead(TriangleInput& in, size_t capacity, const Channels& channels,
                                   const Channels& stored)
    : in_(in),
      source_(*in.reader().indexed()),
      capacity_(capacity),
      channels_(channels),
      layout_(stored),
      batches_(kPipelineChunks - 1) {
    assert(possible(in, channels));
    for (Batch& b : batches_) b.chunks.emplace_back(capacity, channels);
    lookup_ = source_.split_lookup();
    for (size_t i = 0; i < batches_.size(); ++i) batches_[i].seq = i;
    reader_ = std::thread([this] { read_faces(); });
    resolver_ = std::thread([this] { resolve_odd(); });
}

IndexedReadAhead::~IndexedReadAhead() {
    {
        std::lock_guard lock(mutex_);
        stopped_ = true;
        changed_.notify_all();
    }
    join();
}

void IndexedReadAhead::join() {
    if (reader_.joinable()) reader_.join();
    if (resolver_.joinable()) resolver_.join();
}

template <class Done>
bool IndexedReadAhead::wait_for(uint64_t seq, Done done) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return stopped_ || (batch(seq).seq == seq && done(batch(seq).state)); });
    return !stopped_;
}

void IndexedReadAhead::set(Batch& b, State state) {
    std::lock_guard lock(mutex_);
    b.state = state;
    changed_.notify_all();
}

template <class Lookup>
void IndexedReadAhead::resolve(Batch& b, Lookup& lookup) {
    const size_t triangles = b.indices.size() / 3;
    b.used = (triangles + capacity_ - 1) / capacity_;
    while (b.chunks.size() < b.used) b.chunks.emplace_back(capacity_, channels_);
    for (size_t c = 0; c < b.used; ++c) b.chunks[c].clear();
    const size_t rb = layout_.bytes();
    std::vector<std::byte> record(rb);
    const uint32_t* idx = b.indices.data();
    constexpr size_t kAhead = 24;  // corners: the lookups ahead overlap their waits for memory
    const size_t corners = b.indices.size();
    for (size_t c = 0; c < std::min(kAhead, corners); ++c) lookup.prefetch(idx[c]);
    for (size_t t = 0; t < triangles; ++t) {
        TriangleChunk& chunk = b.chunks[t / capacity_];
        const size_t i = chunk.size();
        float* xyz = chunk.push_slot();
        uint64_t* ids = chunk.id_at(i);
        for (int k = 0; k < 3; ++k) {
            const size_t c = 3 * t + size_t(k);
            if (c + kAhead < corners) lookup.prefetch(idx[c + kAhead]);
            lookup.vertex(idx[c], xyz + 3 * k, rb > 0 ? record.data() : nullptr);
            if (rb > 0) layout_.unpack(record.data(), chunk, i, k);
            if (ids) ids[k] = idx[c];
        }
    }
}

void IndexedReadAhead::read_faces() {
    SourceLookup own{source_};
    for (uint64_t seq = 0;; ++seq) {
        if (!wait_for(seq, [](State s) { return s == State::kFree; })) return;
        Batch& b = batch(seq);
        try {
            b.indices.clear();
            const bool more = source_.next_triangles(b.indices, capacity_);
            b.stored_offset = in_.has_source() ? in_.source().stored_offset() : 0;
            if (!more) {
                set(b, State::kEnd);
                return;
            }
            if (seq % 2 == 1) {
                set(b, State::kRead);  // the second thread's
                continue;
            }
            resolve(b, own);
            set(b, State::kResolved);
        } catch (...) {
            b.error = std::current_exception();
            set(b, State::kFailed);
            return;
        }
    }
}

void IndexedReadAhead::resolve_odd() {
    for (uint64_t seq = 1;; seq += 2) {
        State state = State::kFree;
        if (!wait_for(seq, [&](State s) {
                state = s;
                return s == State::kRead || s == State::kEnd || s == State::kFailed;
            }))
            return;
        if (state != State::kRead) return;  // the faces ended, or the reading failed, here
        Batch& b = batch(seq);
        try {
            resolve(b, *lookup_);
            set(b, State::kResolved);
        } catch (...) {
            b.error = std::current_exception();
            set(b, State::kFailed);
            return;
        }
    }
}

bool IndexedReadAhead::next(TriangleChunk& chunk) {
    for (;;) {
        const uint64_t seq = next_seq_;
        State state = State::kFree;
        const bool ok = wait_for(seq, [&](State s) {
            state = s;
            return s == State::kResolved || s == State::kEnd || s == State::kFailed;
        });
        if (!ok) {  // stopped: the input ended or failed at an earlier call
            chunk.clear();
            return false;
        }
        Batch& b = batch(seq);
        if (state != State::kResolved) {
            // Nothing after it is wanted: the threads stop where they wait, and are joined.
            {
                std::lock_guard lock(mutex_);
                stopped_ = true;
                changed_.notify_all();
            }
            join();
            chunk.clear();
            if (state == State::kFailed) std::rethrow_exception(b.error);
            in_.end_of_input();
            return false;
        }
        if (b.taken < b.used) {
            assert(b.chunks[b.taken].capacity() == chunk.capacity() && b.chunks[b.taken].channels() == chunk.channels());
            std::swap(b.chunks[b.taken++], chunk);
            stored_offset_ = b.stored_offset;
            in_.admit(chunk);
            if (!chunk.empty()) return true;
            continue;
        }
        // The batch is done: its slot takes the batch kPipelineChunks - 1 further on.
        {
            std::lock_guard lock(mutex_);
            b.taken = b.used = 0;
            b.seq = seq + batches_.size();
            b.state = State::kFree;
            ++next_seq_;
            changed_.notify_all();
        }
    }
}

WriteBehind::WriteBehind(Output& out, size_t capacity, const Channels& channels)
    : queue_(kPipelineChunks - 1, capacity, channels) {
    thread_ = std::thread([this, &out] {
        try {
            while (PipelineSlot* slot = queue_.get_full()) {
                out.write(slot->chunk);
                queue_.put_free(slot);
            }
        } catch (...) {
            queue_.fail(std::current_exception());
        }
    });
}

WriteBehind::~WriteBehind() {
    queue_.stop();
    join();
}

void WriteBehind::join() {
    if (thread_.joinable()) thread_.join();
}

void WriteBehind::write(TriangleChunk& chunk) {
    PipelineSlot* slot = nullptr;
    try {
        slot = queue_.get_free();
    } catch (...) {
        join();
        throw;
    }
    assert(slot != nullptr);  // stop() comes from the destructor only
    assert(slot->chunk.capacity() == chunk.capacity() && slot->chunk.channels() == chunk.channels());
    std::swap(slot->chunk, chunk);
    chunk.clear();
    queue_.put_full(slot);
}

void WriteBehind::close() {
    queue_.close();
    join();
    queue_.rethrow_failure();
}

}  // namespace meshstream::io
