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
// A key may be a lower bound (kDirty): an edge whose end just gained a quadric's planes costs
// at least what it cost before (quadrics only grow), so it keeps its place and is rated again
// only when it comes up (lazy evaluation; Garland & Heckbert re-rate every edge of the merged
// vertex at once, and most of those ratings are superseded before they are used).
//
// Memory: for a buffer of N triangles, about (4·N / 15 + 16 400) chunks of 64 bytes (8 MB at
// the default 400 000) plus 80 KB of bucket heads and bitmaps, allocated once.
#pragma once

#include "decimate/halfedge_buffer.hpp"

#include <cstddef>
#include <cstdint>

namespace meshstream::decimate {

class CollapseQueue {
public:
    static constexpr uint32_t kBuckets = 1u << 14;
    static constexpr uint16_t kBucketMask = kBuckets - 1;  // in a Face::key: the bucket,
    static constexpr uint16_t kReverse = 1u << 14;         // the twin collapses,
    static constexpr uint16_t kDirty = 1u << 15;           // the key is a lower bound only

    explicit CollapseQueue(size_t face_capacity);
    static size_t reserved_bytes(size_t face_capacity);

    // The bucket of an error: monotone (a larger error never gets a smaller bucket); negative
    // round-off counts as 0, NaN last.
    static uint32_t bucket_of(double error);

    // Queues the collapse of the edge of half-edge h, in the direction of h or (`reverse`) of
    // its twin, rated `error`. Whatever was queued for the edge before no longer counts.
    void push(HalfEdgeBuffer& buffer, uint32_t h, bool reverse, double error);
    // Nothing is queued for the edge of h any more.
    static void forget(HalfEdgeBuffer& buffer, uint32_t h);
    // The edge of h (when queued) keeps its key as a lower bound of its error, which has grown
    // (an end's quadric gained planes, or an end was written): it is rated again when it
    // comes up. Its direction may change then.
    static void mark_dirty(HalfEdgeBuffer& buffer, uint32_t h) {
        uint16_t& key = buffer.queue_key(h);
        if (key != kNotQueued) key |= kDirty;
    }
    // Removes the cheapest current entry and returns the half-edge p→q to collapse, or
    // kNoIndex when nothing is queued; `dirty` tells whether its key was only a lower bound (or
    // the edge must be rated afresh: the twin it was queued to collapse is gone).
    // The edge is no longer queued afterwards.
    uint32_t pop(HalfEdgeBuffer& buffer, bool& dirty);
    // Empties the queue; every face's keys become kNotQueued.
    void clear(HalfEdgeBuffer& buffer);

    // Entries held, including those that will be skipped.
    size_t entries() const { return entries_; }

private:
    static constexpr uint32_t kChunkEntries = 15;
    static constexpr uint32_t kNone = 0xFFFFFFFFu;
    struct alignas(64) Chunk {
        uint32_t next;
        uint32_t entry[kChunkEntries];
    };
    bool current(const HalfEdgeBuffer& buffer, uint32_t h, uint32_t bucket) const;
    void append(uint32_t bucket, uint32_t h);
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
