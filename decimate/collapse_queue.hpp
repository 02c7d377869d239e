// The order of collapses: a bucketed priority queue of edges keyed by their collapse error, so
// that the cheapest collapse in the buffer is taken first (Garland & Heckbert 1997's greedy
// order, which Wu & Kobbelt 2003, §4.3, approximate by the best of a few random candidates).
// Keys are the top 14 bits of the error as a float (sign always 0, 8 exponent bits, 6 mantissa
// bits: buckets 1.6 % apart, as meshoptimizer's simplifier sorts its collapses by the top
// bits of the error); within a bucket the last one queued comes first.
//
// Nothing is ever searched for or removed from the middle: an edge's current key lives in its
// face record (HalfEdgeBuffer::queue_key of the half-edge it was last queued under; the twin's
// key is then kNotQueued), and an entry whose face is gone or whose edge was queued again
// under another key is skipped when it comes up.
// Entries are half-edge indices in chunks of 15 from a fixed pool; when the pool runs out, the
// skipped-to-be entries are dropped (purge()), which frees at least a quarter of it.
//
// Edges whose cost changed are queued again (Garland & Heckbert), at once or when they come up:
// after a collapse p→q the caller rates q's edges while q's fan is still in the cache from
// checking and applying the collapse, and their old entries are skipped when they come up;
// except that an edge whose old key is known to be a lower bound on its new rating keeps its
// entry, marked kStale (keep_as_lower_bound()), and pop() hands it back to be rated when it
// comes up. The order stays cheapest first as long as the bound holds (greedy.cpp says when).
//
// Memory: for a buffer of N triangles, about (4·N / 15 + 16 400) chunks of 64 bytes (8 MB at
// the default 400 000) plus 80 KB of bucket heads and bitmaps, allocated once.
#pragma once

#include "decimate/halfedge_buffer.hpp"

#include <bit>
#include <cfloat>
#include <cstddef>
#include <cstdint>

namespace meshstream::decimate {

class CollapseQueue {
public:
    static constexpr uint32_t kBuckets = 1u << 14;
    static constexpr uint16_t kBucketMask = kBuckets - 1;  // in a Face::key: the bucket,
    static constexpr uint16_t kReverse = 1u << 14;         // the twin collapses
    static constexpr uint16_t kStale = 1u << 15;           // a lower bound: rate again when it comes up

    explicit CollapseQueue(size_t face_capacity);
    static size_t reserved_bytes(size_t face_capacity);

    // The bucket of an error: monotone (a larger error never gets a smaller bucket); negative
    // round-off counts as 0, NaN last.
    static uint32_t bucket_of(double error) {
        if (error != error) return kBuckets - 2;  // NaN (bucket kBuckets − 1 could read kNotQueued)
        if (!(error > 0)) return 0;
        const float f = error < double(FLT_MAX) ? static_cast<float>(error) : FLT_MAX;
        // Positive floats order as their bit patterns: the top 14 bits below the sign bit.
        return std::bit_cast<uint32_t>(f) >> 17;
    }

    // Queues the collapse of the edge of half-edge h, in the direction of h or (`reverse`) of
    // its twin, rated `error`. Whatever was queued for the edge before no longer counts; an
    // edge queued under the same key already keeps its entry.
    // Inline: every rating ends here.
    void push(HalfEdgeBuffer& buffer, uint32_t h, bool reverse, double error) {
        // The key goes to h; the twin's is cleared, so that an entry left under it by an earlier
        // rating is skipped.
        const uint32_t t = buffer.twin(h);
        if (is_half_edge(t)) buffer.queue_key(t) = kNotQueued;
        const uint32_t bucket = bucket_of(error);
        const uint16_t key = static_cast<uint16_t>(bucket | (reverse ? kReverse : 0));
        if (buffer.queue_key(h) == key) return;
        buffer.queue_key(h) = key;
        if (fill_[bucket] == kChunkEntries || head_[bucket] == kNone) new_chunk(buffer, bucket);
        chunks_[head_[bucket]].entry[fill_[bucket]++] = h;
        ++entries_;
    }
    // Nothing is queued for the edge of h any more.
    static void forget(HalfEdgeBuffer& buffer, uint32_t h);
    // The edge of h (interior) keeps its entry as a lower bound on its rating: pop() hands it
    // back to be rated afresh when it comes up. False, changing nothing, unless exactly one of
    // h and its twin holds a key.
    static bool keep_as_lower_bound(HalfEdgeBuffer& buffer, uint32_t h) {
        uint16_t& own = buffer.queue_key(h);
        uint16_t& twin = buffer.queue_key(buffer.twin(h));
        if ((own == kNotQueued) == (twin == kNotQueued)) return false;
        (own != kNotQueued ? own : twin) |= kStale;
        return true;
    }
    // Removes the cheapest current entry and returns the half-edge p→q to collapse, or
    // kNoIndex when nothing is queued; `rerate` tells that the edge must be rated afresh
    // instead (it was kept as a lower bound, or the twin it was queued to collapse is gone).
    // The edge is no longer queued afterwards.
    uint32_t pop(HalfEdgeBuffer& buffer, bool& rerate);
    // Empties the queue; every face's keys become kNotQueued.
    void clear(HalfEdgeBuffer& buffer);

    // Entries held, including those that will be skipped.
    size_t entries() const { return entries_; }

private:
    static constexpr uint32_t kChunkEntries = 15;
    static constexpr uint32_t kLookAhead = 4;
    static constexpr uint32_t kNone = 0xFFFFFFFFu;
    struct alignas(64) Chunk {
        uint32_t next;
        uint32_t entry[kChunkEntries];
    };
    bool current(const HalfEdgeBuffer& buffer, uint32_t h, uint32_t bucket) const;
    void append(uint32_t bucket, uint32_t h);
    // Starts a chunk at the head of `bucket` unless a purge, made first when the pool is used
    // up, left the bucket room.
    void new_chunk(HalfEdgeBuffer& buffer, uint32_t bucket);
    // Starts a chunk at the head of `bucket` (one is free).
    void start_chunk(uint32_t bucket);
    void purge(HalfEdgeBuffer& buffer);
    int lowest_bucket() const;

    size_t chunk_capacity_;
    RawArray<Chunk> chunks_;
    RawArray<uint32_t> free_chunks_;
    size_t free_chunk_count_ = 0;
    uint32_t chunk_high_ = 0;
    uint32_t head_[kBuckets];  // newest chunk of each bucket (kNone: empty)
    uint8_t fill_[kBuckets];   // entries in the head chunk
    uint64_t nonempty_[kBuckets / 64];
    uint64_t nonempty_words_[kBuckets / 64 / 64];
    size_t entries_ = 0;
};

}  // namespace meshstream::decimate
