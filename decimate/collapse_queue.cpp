// The bucketed collapse queue (Garland & Heckbert 1997's greedy order; buckets by the top bits
// of the error as in meshoptimizer's sortEdgeCollapses).
#include "decimate/collapse_queue.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstring>

namespace meshstream::decimate {

CollapseQueue::CollapseQueue(size_t face_capacity)
    // Current entries: at most one per edge, and a buffer of N faces has at most 3·N edges;
    // the rest of 4·N is room for entries to be skipped. Each bucket may hold one part-filled
    // chunk besides.
    : chunk_capacity_(4 * face_capacity / kChunkEntries + kBuckets + 16),
      chunks_(raw_array<Chunk>(chunk_capacity_)),
      free_chunks_(raw_array<uint32_t>(chunk_capacity_)) {
    std::fill(std::begin(head_), std::end(head_), kNone);
    std::fill(std::begin(fill_), std::end(fill_), uint8_t{0});
    std::fill(std::begin(nonempty_), std::end(nonempty_), uint64_t{0});
    std::fill(std::begin(nonempty_words_), std::end(nonempty_words_), uint64_t{0});
}

size_t CollapseQueue::reserved_bytes(size_t face_capacity) {
    const size_t chunks = 4 * face_capacity / kChunkEntries + kBuckets + 16;
    return chunks * (sizeof(Chunk) + 4) + sizeof(CollapseQueue);
}

void CollapseQueue::new_chunk(HalfEdgeBuffer& buffer, uint32_t bucket) {
    if (free_chunk_count_ == 0 && chunk_high_ == chunk_capacity_) purge(buffer);
    // A purge may have left the bucket a part-filled head chunk.
    if (head_[bucket] == kNone || fill_[bucket] == kChunkEntries) start_chunk(bucket);
}

void CollapseQueue::start_chunk(uint32_t bucket) {
    assert(free_chunk_count_ > 0 || chunk_high_ < chunk_capacity_);
    const uint32_t c = free_chunk_count_ > 0 ? free_chunks_[--free_chunk_count_] : chunk_high_++;
    chunks_[c].next = head_[bucket];
    head_[bucket] = c;
    fill_[bucket] = 0;
    nonempty_[bucket / 64] |= uint64_t{1} << (bucket % 64);
    nonempty_words_[bucket / 4096] |= uint64_t{1} << (bucket / 64 % 64);
}

void CollapseQueue::forget(HalfEdgeBuffer& buffer, uint32_t h) {
    buffer.queue_key(h) = kNotQueued;
    const uint32_t t = buffer.twin(h);
    if (is_half_edge(t)) buffer.queue_key(t) = kNotQueued;
}

void CollapseQueue::append(uint32_t bucket, uint32_t h) {
    if (head_[bucket] == kNone || fill_[bucket] == kChunkEntries) start_chunk(bucket);
    chunks_[head_[bucket]].entry[fill_[bucket]++] = h;
    ++entries_;
}

int CollapseQueue::lowest_bucket() const {
    for (uint32_t i = 0; i < kBuckets / 4096; ++i) {
        if (nonempty_words_[i] == 0) continue;
        const uint32_t word = 64 * i + static_cast<uint32_t>(std::countr_zero(nonempty_words_[i]));
        return static_cast<int>(64 * word + static_cast<uint32_t>(std::countr_zero(nonempty_[word])));
    }
    return -1;
}

bool CollapseQueue::current(const HalfEdgeBuffer& buffer, uint32_t h, uint32_t bucket) const {
    const uint16_t key = buffer.queue_key(h);
    return buffer.face_alive(face_of(h)) && key != kNotQueued && (key & kBucketMask) == bucket;
}

uint32_t CollapseQueue::pop(HalfEdgeBuffer& buffer, bool& rerate) {
    for (;;) {
        const int found = lowest_bucket();
        if (found < 0) return kNoIndex;
        const uint32_t bucket = static_cast<uint32_t>(found);
        const uint32_t c = head_[bucket];
        const uint32_t h = chunks_[c].entry[--fill_[bucket]];
        --entries_;
        // Most entries are skipped (their edge was queued again since), each after a look at
        // its face record: the records of the entries a few places on are fetched meanwhile,
        // running on into the bucket's next chunk (full: only the head is part-filled), which
        // is fetched as this one is started. Hints only.
        const uint32_t rest = fill_[bucket], next = chunks_[c].next;
        if (rest == kChunkEntries - 1 && next != kNone) __builtin_prefetch(&chunks_[next]);
        if (rest >= kLookAhead)
            buffer.prefetch_face(face_of(chunks_[c].entry[rest - kLookAhead]));
        else if (next != kNone)
            buffer.prefetch_face(face_of(chunks_[next].entry[kChunkEntries - kLookAhead + rest]));
        if (fill_[bucket] == 0) {
            // The head chunk is empty: the next one (full) becomes the head.
            free_chunks_[free_chunk_count_++] = c;
            head_[bucket] = chunks_[c].next;
            fill_[bucket] = head_[bucket] == kNone ? 0 : kChunkEntries;
            if (head_[bucket] == kNone) {
                nonempty_[bucket / 64] &= ~(uint64_t{1} << (bucket % 64));
                if (nonempty_[bucket / 64] == 0) nonempty_words_[bucket / 4096] &= ~(uint64_t{1} << (bucket / 64 % 64));
            }
        }
        if (!current(buffer, h, bucket)) continue;
        // The entry that probably comes up next (unless this one queues cheaper edges): its
        // face record was fetched a few pops ago; its two vertex records are fetched now, while
        // this one is worked on. A hint only.
        if (fill_[bucket] > 0) {
            const uint32_t following = chunks_[head_[bucket]].entry[fill_[bucket] - 1];
            buffer.prefetch_vertex(buffer.corner_vertex(following));
            buffer.prefetch_vertex(buffer.corner_vertex(next_in_face(following)));
        }
        const uint16_t key = buffer.queue_key(h);
        buffer.queue_key(h) = kNotQueued;
        rerate = (key & kStale) != 0;
        if (rerate) return h;
        if ((key & kReverse) == 0) return h;
        const uint32_t t = buffer.twin(h);
        if (is_half_edge(t)) return t;
        // The twin is gone since (written, or the edge opened): h is rated afresh.
        rerate = true;
        return h;
    }
}

void CollapseQueue::purge(HalfEdgeBuffer& buffer) {
    // Each bucket's list is taken apart chunk by chunk (freeing it) and its current entries
    // appended again. Chunks are freed before they are refilled, so the pool never runs short
    // here. (An edge queued twice in one bucket keeps both entries: rare, and harmless, as the
    // second is skipped once the first has come up.)
    for (uint32_t bucket = 0; bucket < kBuckets; ++bucket) {
        uint32_t c = head_[bucket];
        if (c == kNone) continue;
        uint32_t count = fill_[bucket];
        head_[bucket] = kNone;
        fill_[bucket] = 0;
        nonempty_[bucket / 64] &= ~(uint64_t{1} << (bucket % 64));
        if (nonempty_[bucket / 64] == 0) nonempty_words_[bucket / 4096] &= ~(uint64_t{1} << (bucket / 64 % 64));
        while (c != kNone) {
            uint32_t taken[kChunkEntries];
            std::memcpy(taken, chunks_[c].entry, count * sizeof(uint32_t));
            const uint32_t next = chunks_[c].next;
            free_chunks_[free_chunk_count_++] = c;
            entries_ -= count;
            for (uint32_t i = 0; i < count; ++i)
                if (current(buffer, taken[i], bucket)) append(bucket, taken[i]);
            c = next;
            count = kChunkEntries;
        }
    }
}

void CollapseQueue::clear(HalfEdgeBuffer& buffer) {
    std::fill(std::begin(head_), std::end(head_), kNone);
    std::fill(std::begin(fill_), std::end(fill_), uint8_t{0});
    std::fill(std::begin(nonempty_), std::end(nonempty_), uint64_t{0});
    std::fill(std::begin(nonempty_words_), std::end(nonempty_words_), uint64_t{0});
    free_chunk_count_ = 0;
    chunk_high_ = 0;
    entries_ = 0;
    for (uint32_t f = 0; f < buffer.face_slots(); ++f)
        for (uint32_t k = 0; k < 3; ++k) buffer.queue_key(half_edge(f, k)) = kNotQueued;
}

}  // namespace meshstream::decimate
