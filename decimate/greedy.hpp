// DECIMATE (Wu & Kobbelt 2003, §4.3) as Garland & Heckbert's greedy order: every eligible edge
// of the buffer is rated once, when its second end leaves P_in, and again whenever an end
// changes (after a collapse, an edge between free ends whose rating can only have risen: when
// it comes up); the cheapest valid collapse in the buffer comes next. Wu & Kobbelt take the best of
// a few random candidates instead; with cached ratings in a bucketed queue (collapse_queue.hpp)
// the exact order costs less than the random draws did, and the buffer's cheapest collapses
// are then always in the part read last, which keeps the work in cache.
//
// A collapse refused by a veto (collapse.hpp) leaves its edge out of the queue until a
// neighbour of one of its ends changes (kBlocked): only then can the outcome differ.
#pragma once

#include "decimate/collapse.hpp"
#include "decimate/collapse_queue.hpp"
#include "decimate/halfedge_buffer.hpp"

#include <cstdint>

namespace meshstream::decimate {

// Rates the edge of half-edge h: the eligible direction (both, when both are: the cheaper,
// the same merge when both ends are free) placed by collapse_placement() and queued; or
// forgotten when neither direction is eligible.
void rate_edge(HalfEdgeBuffer& buffer, CollapseQueue& queue, uint32_t h);
// Rates the edges of the vertices HalfEdgeBuffer::take_pending() lists.
void rate_pending(HalfEdgeBuffer& buffer, CollapseQueue& queue);
// Empties the queue and rates every edge of the buffer (refused ones too).
void rate_all(HalfEdgeBuffer& buffer, CollapseQueue& queue);

// Takes queued collapses, cheapest first, until one is eligible and valid; performs it, rates
// the edges round the merged vertex (and those of blocked neighbours) and returns true. False
// when the queue ran empty.
bool collapse_cheapest(HalfEdgeBuffer& buffer, CollapseQueue& queue);

// The valid collapse with the smallest error among every eligible half-edge of the buffer,
// found by a scan; false when none is valid. For the end of input, when the queue has run
// empty of valid collapses in a small buffer.
bool collapse_best_of_all(HalfEdgeBuffer& buffer);

// A boundary collapse removing exactly one face, used once at the end of input to land on an
// odd target count: the valid collapse p→q along a true-boundary half-edge (no partner, p not
// on P_in or P_out) with the smallest error, found by a scan of the buffer. Returns false when
// there is none (closed meshes have an even face count).
bool collapse_one_boundary_edge(HalfEdgeBuffer& buffer);

}  // namespace meshstream::decimate
