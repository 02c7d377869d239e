// The greedy collapse order over the buffer (Garland & Heckbert 1997, in place of the multiple
// choice of Wu & Kobbelt 2003, §4.3), with the end-of-input scans.
#include "decimate/greedy.hpp"

#include "decimate/attribute_store.hpp"
#include "decimate/phase_timers.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace meshstream::decimate {

namespace {

// Flags of a vertex that may not be the source of a collapse (collapse_eligible).
constexpr uint16_t kNoSource = kInHash | kFrozen | kNonManifold | kManyFans | kSeam;

// A free end: none of those flags, no open edge, a small fan. An interior edge between two free
// ends is eligible both ways, as the same merge (collapse_target_free).
bool free_end(const Vertex& x) {
    return (x.flags & kNoSource) == 0 && x.open_edges == 0 && x.face_count <= kMaxMovedFaces;
}

// Queues the merge of both free ends p and q of h at the minimum of Q_p + Q_q, rated at the
// exact minimum (collapse_placement() rounds it to floats).
void rate_merge(HalfEdgeBuffer& buffer, CollapseQueue& queue, uint32_t h, uint32_t p, uint32_t q) {
    const Quadric sum = merged_quadric(buffer, p, q);
    double x[3];
    queue.push(buffer, h, false, sum.minimum(x) ? sum.error_at_minimum(x) : singular_merge(buffer, sum, p, q).error);
}

}  // namespace

void rate_edge(HalfEdgeBuffer& buffer, CollapseQueue& queue, uint32_t h) {
    // collapse_eligible() both ways, from the two vertex records and h's twin.
    const uint32_t t = buffer.twin(h);
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    const Vertex& vp = buffer.vertex(p);
    const Vertex& vq = buffer.vertex(q);
    if (buffer.full_resolution_first() && ((vp.flags | vq.flags) & kFullResolution) == 0) {
        CollapseQueue::forget(buffer, h);
        return;
    }
    // Most edges first: an interior edge between free ends (free_end() of both, in one test).
    if (is_half_edge(t) && ((vp.flags | vq.flags) & kNoSource) == 0 && (vp.open_edges | vq.open_edges) == 0 &&
        vp.face_count <= kMaxMovedFaces && vq.face_count <= kMaxMovedFaces) {
        rate_merge(buffer, queue, h, p, q);
        return;
    }
    constexpr uint16_t kNoTarget = kInHash | kNonManifold;
    const bool twin_real = is_half_edge(t);
    // A seam vertex collapses only along its seam (seam_slides).
    auto slides = [&](const Vertex& from, const Vertex& to, uint32_t along) {
        return (from.flags & (kNoSource & ~kSeam)) == 0 && (from.flags & kSeam) && from.open_edges == 0 &&
               (to.flags & kNoTarget) == 0 && seam_slides(buffer, along);
    };
    // Boundary loops touching at p (kOpenFans): p slides along an open edge, as on one loop.
    const bool touching = (vp.flags & (kManyFans | kOpenFans | kSeam)) == (kManyFans | kOpenFans);
    const bool forward = ((vp.flags & (touching ? kNoSource & ~kManyFans : kNoSource)) == 0 &&
                          (vq.flags & kNoTarget) == 0 &&
                          (vp.open_edges == 0 ? twin_real : (vp.open_edges == 2 || touching) && t == kOpenEdge) &&
                          ((vq.flags & kSeam) == 0 || seam_allows(buffer, h))) ||
                         ((vp.flags & kSeam) && slides(vp, vq, h));
    const bool backward = twin_real && (((vq.flags & kNoSource) == 0 && (vp.flags & kNoTarget) == 0 &&
                                         vq.open_edges == 0 && ((vp.flags & kSeam) == 0 || seam_allows(buffer, t))) ||
                                        ((vq.flags & kSeam) && slides(vq, vp, t)));
    if (!forward && !backward) {
        CollapseQueue::forget(buffer, h);
        return;
    }
    if (forward && backward && ((vp.flags | vq.flags) & kSeam) == 0 && vp.face_count <= kMaxMovedFaces &&
        vq.face_count <= kMaxMovedFaces) {
        // Both ends free (collapse_target_free either way): the same merge.
        rate_merge(buffer, queue, h, p, q);
        return;
    }
    const double e_forward = forward ? collapse_placement(buffer, h).error : INFINITY;
    const double e_backward = backward ? collapse_placement(buffer, t).error : INFINITY;
    if (e_backward < e_forward)
        queue.push(buffer, h, true, e_backward);
    else
        queue.push(buffer, h, false, e_forward);
}

namespace {

// Which edges of a vertex rate_edges_around() rates.
enum class Rerate {
    kAll,
    // Not those whose other end is still listed for take_pending() (it rates them when its turn
    // comes: each edge once).
    kSkipPending,
    // v is the vertex a collapse p→q left (q, moved and holding Q_p + Q_q). A queued edge
    // between two free ends (free_end) keeps its entry as a lower bound
    // (CollapseQueue::keep_as_lower_bound) and is rated when it comes up. Its key rated it as a
    // merge of free ends, at the minimum of their summed quadrics (an edge of q's or of p's
    // before), and v's quadric now holds both ends' old ones: a quadric is never negative, so
    // the minimum can only have risen. (Not always where a sum had no minimum and the best of
    // three points stood in for it, as on flat stretches; nor with channels, whose rating
    // divides the geometric error by the planes' weight, which grows too
    // (AttributeStore::combined): a key above the new rating only delays that collapse.) Such an edge is rated once when it comes up instead of once per
    // collapse next to it, or never, when a collapse nearby removes it or it is written first.
    kAfterCollapse,
};

// Rates the edges of v (as `mode` says). Edges to a vertex on P_in are passed over: neither
// way is eligible, and such an edge was never queued (a vertex is on P_in from its creation
// only), so rating it would only forget it again.
void rate_edges_around(HalfEdgeBuffer& buffer, CollapseQueue& queue, uint32_t v, Rerate mode) {
    const uint16_t pass_over = kInHash | (mode == Rerate::kSkipPending ? kPending : 0);
    const bool lazy = mode == Rerate::kAfterCollapse && free_end(buffer.vertex(v));
    // Whether the edge of h (from v) is left as it is.
    auto kept = [&](uint32_t h) {
        return lazy && is_half_edge(buffer.twin(h)) && free_end(buffer.vertex(buffer.corner_vertex(next_in_face(h)))) &&
               CollapseQueue::keep_as_lower_bound(buffer, h);
    };
    // Every rating reads both ends' vertex records (and attribute records, with channels), far
    // apart in their pools: asked for all at once, their cache misses overlap (a hint only).
    const AttributeStore* attributes = buffer.attributes();
    for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        const uint32_t to = buffer.corner_vertex(next_in_face(c));
        buffer.prefetch_vertex(to);
        if (attributes) attributes->prefetch(to);
    }
    for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        const uint32_t to = buffer.corner_vertex(next_in_face(c));
        if ((buffer.vertex(to).flags & pass_over) == 0 && !kept(c)) rate_edge(buffer, queue, c);  // v→next
        // prev→v is also the next one's v→prev, except where v's fan is open.
        const uint32_t in = prev_in_face(c);
        if (is_half_edge(buffer.twin(in))) continue;
        const uint32_t from = buffer.corner_vertex(in);
        if ((buffer.vertex(from).flags & pass_over) == 0) rate_edge(buffer, queue, in);
    }
}

}  // namespace

void rate_pending(HalfEdgeBuffer& buffer, CollapseQueue& queue) {
    const PhaseTimer timer(Phase::kQueue);
    buffer.take_pending([&](uint32_t v) { rate_edges_around(buffer, queue, v, Rerate::kSkipPending); });
}

void rate_all(HalfEdgeBuffer& buffer, CollapseQueue& queue) {
    queue.clear(buffer);
    buffer.take_pending([](uint32_t) {});
    for (uint32_t f = 0; f < buffer.face_slots(); ++f) {
        if (!buffer.face_alive(f)) continue;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(f, k), t = buffer.twin(h);
            if (is_half_edge(t) && t < h) continue;  // each edge once
            rate_edge(buffer, queue, h);
        }
    }
    for (uint32_t v = 0; v < buffer.vertex_slots(); ++v) buffer.vertex(v).flags &= ~kBlocked;
}

bool collapse_cheapest(HalfEdgeBuffer& buffer, CollapseQueue& queue) {
    const PhaseTimer timer(Phase::kQueue);
    for (;;) {
        bool rerate = false;
        const uint32_t h = queue.pop(buffer, rerate);
        if (h == kNoIndex) return false;
        if (rerate) {
            rate_edge(buffer, queue, h);
            continue;
        }
        if (!collapse_eligible(buffer, h)) continue;
        prefetch_neighbourhood(buffer, h);
        const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
        if (const AttributeStore* attributes = buffer.attributes()) attributes->prefetch_merge(p, q);
        const CollapsePlacement placement = collapse_placement(buffer, h);
        if (!collapse_valid(buffer, h, placement.target)) {
            // Its neighbourhood's shape or topology refuses it: that changes only when a
            // neighbour of p or q changes, which rates their edges again.
            buffer.vertex(p).flags |= kBlocked;
            buffer.vertex(q).flags |= kBlocked;
            continue;
        }
        apply_collapse(buffer, h, placement.target);
        // q's edges are rated again (those kept as lower bounds when they come up), while its
        // fan is in the cache from validating and applying the collapse, as are blocked
        // neighbours' (they may have valid collapses now).
        rate_edges_around(buffer, queue, q, Rerate::kAfterCollapse);
        for (uint32_t c = buffer.vertex(q).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
            for (const uint32_t w : {buffer.corner_vertex(next_in_face(c)), buffer.corner_vertex(prev_in_face(c))}) {
                Vertex& x = buffer.vertex(w);
                if ((x.flags & kBlocked) == 0) continue;
                x.flags &= ~kBlocked;
                rate_edges_around(buffer, queue, w, Rerate::kAll);
            }
        }
        buffer.vertex(q).flags &= ~kBlocked;
        buffer.take_pending([&](uint32_t v) { rate_edges_around(buffer, queue, v, Rerate::kSkipPending); });
        return true;
    }
}

bool collapse_best_of_all(HalfEdgeBuffer& buffer) {
    struct Candidate {
        uint32_t h;
        CollapsePlacement placement;
    };
    std::vector<Candidate> all;
    for (uint32_t f = 0; f < buffer.face_slots(); ++f) {
        if (!buffer.face_alive(f)) continue;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(f, k);
            if (collapse_eligible(buffer, h)) all.push_back({h, collapse_placement(buffer, h)});
        }
    }
    // Stable: ties keep buffer order, so the result is deterministic.
    std::stable_sort(all.begin(), all.end(),
                     [](const Candidate& a, const Candidate& b) { return a.placement.error < b.placement.error; });
    for (const Candidate& c : all)
        if (collapse_valid(buffer, c.h, c.placement.target)) {
            apply_collapse(buffer, c.h, c.placement.target);
            return true;
        }
    return false;
}

bool collapse_one_boundary_edge(HalfEdgeBuffer& buffer) {
    struct Candidate {
        uint32_t h;
        double error;
    };
    std::vector<Candidate> all;
    for (uint32_t f = 0; f < buffer.face_slots(); ++f) {
        if (!buffer.face_alive(f)) continue;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(f, k);
            if (buffer.twin(h) == kOpenEdge && collapse_eligible(buffer, h))
                all.push_back({h, collapse_error(buffer, h)});
        }
    }
    // Stable: ties keep buffer order, so the result is deterministic. Every candidate is tried
    // (the cheapest few are often all refused on a welded scan's ragged rim).
    std::stable_sort(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) { return a.error < b.error; });
    for (const Candidate& c : all)
        if (collapse_valid(buffer, c.h)) {
            apply_collapse(buffer, c.h);
            return true;
        }
    return false;
}

}  // namespace meshstream::decimate
