#include "io/pipeline.hpp"

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
