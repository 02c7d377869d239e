// CollapseQueue (collapse_queue.hpp): cheapest first, one current key per edge, entries that no
// longer count skipped, the pool purged when it runs out.
#include "decimate/collapse_queue.hpp"

#include "mesh_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace meshstream::decimate;
using namespace meshstream::decimate::test;

namespace {

// An octahedron: 12 edges, each with a twin. One half-edge of each edge, in slot order.
struct Octahedron {
    HalfEdgeBuffer buffer{64, 0};
    std::vector<uint32_t> edges;
    Octahedron() {
        add_indexed(buffer, octahedron_points(), octahedron_faces());
        for (const uint32_t h : live_half_edges(buffer))
            if (buffer.twin(h) > h) edges.push_back(h);
    }
};

// Pops until the queue is empty: the half-edges returned, in order (none may need rating).
std::vector<uint32_t> pop_all(HalfEdgeBuffer& buffer, CollapseQueue& queue) {
    std::vector<uint32_t> out;
    bool rerate = true;
    for (uint32_t h = queue.pop(buffer, rerate); h != kNoIndex; h = queue.pop(buffer, rerate)) {
        EXPECT_FALSE(rerate) << "half-edge " << h;
        out.push_back(h);
    }
    return out;
}

}  // namespace

TEST(CollapseQueue, BucketsFollowTheErrorAndCountRoundOffAsZero) {
    EXPECT_EQ(CollapseQueue::bucket_of(-1e-12), 0u);
    EXPECT_EQ(CollapseQueue::bucket_of(0), 0u);
    EXPECT_LT(CollapseQueue::bucket_of(1.0), CollapseQueue::bucket_of(1.1));  // 1.6 % apart
    EXPECT_EQ(CollapseQueue::bucket_of(1.0), CollapseQueue::bucket_of(1.01));
    EXPECT_LT(CollapseQueue::bucket_of(1e30), CollapseQueue::bucket_of(1e300));
    EXPECT_EQ(CollapseQueue::bucket_of(std::nan("")), CollapseQueue::kBuckets - 2);
    EXPECT_LT(CollapseQueue::bucket_of(1e300), CollapseQueue::bucket_of(std::nan("")));
}

TEST(CollapseQueue, PopsTheCheapestFirstAndTheLastQueuedFirstWithinABucket) {
    Octahedron o;
    CollapseQueue queue(64);
    const std::vector<uint32_t>& e = o.edges;
    ASSERT_EQ(e.size(), 12u);
    queue.push(o.buffer, e[0], false, 3.0);
    queue.push(o.buffer, e[1], false, 1.0);
    queue.push(o.buffer, e[2], false, 2.0);
    queue.push(o.buffer, e[3], false, 1.0);  // the same bucket as e[1], queued later
    EXPECT_EQ(queue.entries(), 4u);
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{e[3], e[1], e[2], e[0]}));
    EXPECT_EQ(queue.entries(), 0u);
    // Taken edges are no longer queued.
    for (const uint32_t h : e) EXPECT_EQ(o.buffer.queue_key(h), kNotQueued);
}

// An edge kept as a lower bound comes up under its old key, to be rated afresh; an edge that is
// not queued cannot be kept.
TEST(CollapseQueue, AnEdgeKeptAsALowerBoundComesUpToBeRated) {
    Octahedron o;
    CollapseQueue queue(64);
    const std::vector<uint32_t>& e = o.edges;
    queue.push(o.buffer, e[0], false, 1.0);
    queue.push(o.buffer, e[1], true, 2.0);
    EXPECT_FALSE(CollapseQueue::keep_as_lower_bound(o.buffer, e[2]));
    EXPECT_EQ(o.buffer.queue_key(e[2]), kNotQueued);
    EXPECT_EQ(o.buffer.queue_key(o.buffer.twin(e[2])), kNotQueued);
    // Through either half-edge of the edge: the key stays where it is.
    EXPECT_TRUE(CollapseQueue::keep_as_lower_bound(o.buffer, e[0]));
    EXPECT_TRUE(CollapseQueue::keep_as_lower_bound(o.buffer, o.buffer.twin(e[1])));
    EXPECT_EQ(o.buffer.queue_key(o.buffer.twin(e[1])), kNotQueued);
    bool rerate = false;
    EXPECT_EQ(queue.pop(o.buffer, rerate), e[0]);
    EXPECT_TRUE(rerate);
    EXPECT_EQ(o.buffer.queue_key(e[0]), kNotQueued);
    queue.push(o.buffer, e[0], false, 3.0);  // what the caller rates it now
    // e[1] was queued to collapse its twin; kept, it comes up as itself (the edge is rated
    // again, both ways).
    EXPECT_EQ(queue.pop(o.buffer, rerate), e[1]);
    EXPECT_TRUE(rerate);
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{e[0]}));
    EXPECT_EQ(queue.entries(), 0u);
}

TEST(CollapseQueue, AnEdgeQueuedAgainCountsOnlyUnderItsLastKey) {
    Octahedron o;
    CollapseQueue queue(64);
    const std::vector<uint32_t>& e = o.edges;
    queue.push(o.buffer, e[0], false, 1.0);
    queue.push(o.buffer, e[1], false, 2.0);
    queue.push(o.buffer, e[0], false, 3.0);  // its entry under 1.0 no longer counts
    queue.push(o.buffer, e[1], false, 2.0);  // the same key again: the entry it has serves
    EXPECT_EQ(queue.entries(), 3u);
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{e[1], e[0]}));
    EXPECT_EQ(queue.entries(), 0u);
}

TEST(CollapseQueue, AReverseKeyReturnsTheTwinAndTheOtherHalfNoLongerCounts) {
    Octahedron o;
    CollapseQueue queue(64);
    const uint32_t h = o.edges[0], t = o.buffer.twin(h);
    queue.push(o.buffer, h, false, 1.0);
    queue.push(o.buffer, t, false, 2.0);  // the edge queued again under its other half-edge
    EXPECT_EQ(o.buffer.queue_key(h), kNotQueued);
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{t}));
    queue.push(o.buffer, h, true, 1.0);  // the twin collapses
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{t}));
}

TEST(CollapseQueue, ForgottenEdgesAndGoneFacesAreSkipped) {
    Octahedron o;
    CollapseQueue queue(64);
    const uint32_t forgotten = o.edges[0], gone = o.edges[1];
    uint32_t kept = kNoIndex;
    for (const uint32_t h : o.edges)
        if (h != forgotten && face_of(h) != face_of(gone)) kept = h;
    ASSERT_NE(kept, kNoIndex);
    queue.push(o.buffer, forgotten, false, 1.0);
    queue.push(o.buffer, gone, false, 2.0);
    queue.push(o.buffer, kept, false, 3.0);
    CollapseQueue::forget(o.buffer, o.buffer.twin(forgotten));  // either half-edge names the edge
    o.buffer.detach_face(face_of(gone));
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{kept}));
}

TEST(CollapseQueue, AReverseKeyWhoseTwinIsGoneAsksForARating) {
    Octahedron o;
    CollapseQueue queue(64);
    const uint32_t h = o.edges[0];
    queue.push(o.buffer, h, true, 1.0);
    o.buffer.set_twin(h, kOpenEdge);  // the edge opened since (its partner written)
    bool rerate = false;
    EXPECT_EQ(queue.pop(o.buffer, rerate), h);
    EXPECT_TRUE(rerate);
    EXPECT_EQ(queue.pop(o.buffer, rerate), kNoIndex);
}

TEST(CollapseQueue, APoolRunOutIsPurgedOfSkippedEntriesAndKeepsTheCurrentOnes) {
    // One edge queued again and again under two keys leaves a skipped entry each time; a
    // second edge is queued once, below both. The pool (about 16 400 chunks of 15 entries for a
    // small buffer) runs out many times over.
    Octahedron o;
    CollapseQueue queue(64);
    const uint32_t busy = o.edges[0], quiet = o.edges[1];
    queue.push(o.buffer, quiet, false, 0.5);
    size_t most = 0;
    const int kPushes = 1'000'000;
    for (int i = 0; i < kPushes; ++i) {
        queue.push(o.buffer, busy, false, i % 2 == 0 ? 1.0 : 2.0);
        most = std::max(most, queue.entries());
    }
    EXPECT_LT(most, size_t(kPushes) / 2) << "never purged";
    EXPECT_EQ(pop_all(o.buffer, queue), (std::vector<uint32_t>{quiet, busy}));
    EXPECT_EQ(o.buffer.queue_key(busy), kNotQueued);
}

TEST(CollapseQueue, ClearEmptiesTheQueueAndEveryKey) {
    Octahedron o;
    CollapseQueue queue(64);
    for (size_t i = 0; i < o.edges.size(); ++i) queue.push(o.buffer, o.edges[i], i % 2 == 1, double(i));
    queue.clear(o.buffer);
    EXPECT_EQ(queue.entries(), 0u);
    for (const uint32_t h : live_half_edges(o.buffer)) EXPECT_EQ(o.buffer.queue_key(h), kNotQueued);
    bool rerate = false;
    EXPECT_EQ(queue.pop(o.buffer, rerate), kNoIndex);
}
