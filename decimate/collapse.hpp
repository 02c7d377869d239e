// DECIMATE by multiple-choice half-edge collapses (Wu & Kobbelt 2003, §4.3): sample a few
// random eligible half-edges, rate each collapse p→q by the quadric error (Q_p + Q_q)(q), and
// perform the cheapest one that keeps the mesh valid. Eligibility encodes the boundary rules
// of §4: half-edges from a boundary vertex (P_in, P_out, holes, non-manifold) never collapse;
// half-edges into a P_in vertex never collapse (its quadric is incomplete); half-edges into a
// P_out vertex may (q keeps its frozen position, so P_out does not move).
// Beyond the paper: when q is free to move (not on P_in, P_out, a hole or a non-manifold
// edge), the collapse is rated at, and q moved to, the minimum of Q_p + Q_q (Garland &
// Heckbert's optimal placement); a constrained q keeps the half-edge collapse.
#pragma once

#include "decimate/halfedge_buffer.hpp"
#include "decimate/random.hpp"

#include <cstdint>

namespace meshstream::decimate {

// Topological eligibility of half-edge h = p→q from flags alone (cheap, used for sampling):
// p interior (closed fan, not on P_in/P_out, manifold), q manifold and not on P_in.
// (Inline: it runs for every random draw.)
// Beyond the paper: a true-boundary p (a hole, off P_in and P_out, one open fan) may also
// collapse along its outgoing boundary edge (twin kOpenEdge), as in Garland & Heckbert; its
// quadric holds the boundary planes added when it left P_in, which keep the hole's outline.
inline bool collapse_eligible(const HalfEdgeBuffer& buffer, uint32_t h) {
    const Vertex& p = buffer.vertex(buffer.corner_vertex(h));
    if ((p.flags & (kInHash | kFrozen | kNonManifold)) != 0) return false;
    if (p.open_edges == 0) {
        if (!is_half_edge(buffer.twin(h))) return false;
    } else if (p.open_edges != 2 || buffer.twin(h) != kOpenEdge) {
        return false;
    }
    const Vertex& q = buffer.vertex(buffer.corner_vertex(next_in_face(h)));
    return (q.flags & (kInHash | kNonManifold)) == 0;
}

// The quadric error of collapsing h = p→q: (Q_p + Q_q) evaluated at q.
inline double collapse_error(const HalfEdgeBuffer& buffer, uint32_t h) {
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    double x[3];
    buffer.position(q, x);
    return (buffer.quadric(p) + buffer.quadric(q)).error(x);
}

// True when the target q of an eligible h = p→q may move (beyond the paper, as Garland &
// Heckbert's full edge collapse): q is not on P_in (its quadric is incomplete), not written
// (P_out keeps its position), not on a hole or an open edge, and manifold.
inline bool collapse_target_free(const HalfEdgeBuffer& buffer, uint32_t h) {
    const Vertex& q = buffer.vertex(buffer.corner_vertex(next_in_face(h)));
    return (q.flags & (kInHash | kFrozen | kNonManifold)) == 0 && q.open_edges == 0;
}

// Where an eligible collapse h = p→q puts the merged vertex, and its error. When q is free
// (collapse_target_free): the minimum of Q_p + Q_q (rounded to stored float coordinates), or,
// when that is singular, the best of p, q and their midpoint; otherwise q itself (the
// half-edge collapse of §4.3). `target` is relative to the buffer's origin.
struct CollapsePlacement {
    double target[3];
    double error;
    bool moves_target;  // target differs from q's position
};
CollapsePlacement collapse_placement(const HalfEdgeBuffer& buffer, uint32_t h);

// Full validity of an eligible collapse p→q: p's fan is a single closed (or, for a boundary
// half-edge, a single open) fan; the link condition holds (the common neighbours of p and q
// are exactly the vertices opposite the edge), no tetrahedron collapses; no remaining face
// around p flips or folds (normal turns by more than ~84°) or becomes degenerate; the two
// faces beside each removed face, which become neighbours, do not end up back to back (a
// knife edge: normals more than ~154° apart).
bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h);
// The same for merging p and q at `target` (relative coordinates): the remaining faces of
// both p and q are checked against the new position. kAllow lets knife edges through (every
// other check still holds): for the end of input, when nothing else is left.
enum class KnifeEdges { kRefuse, kAllow };
bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h, const double target[3],
                    KnifeEdges knife_edges = KnifeEdges::kRefuse);

// Performs the half-edge collapse p→q: removes the one or two faces on the edge, re-links
// their outer neighbours, moves p's corners to q and adds Q_p to Q_q, frees p.
// Precondition: collapse_valid(buffer, h).
void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h);
// The same, then moves q to `target`. Precondition: collapse_valid(buffer, h, target) and q
// free (collapse_target_free) unless target is q's position.
void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h, const double target[3]);

// True when moving vertex v from `from` to `to` (relative coordinates) flips, folds or
// degenerates none of its faces other than `skip0`/`skip1` (kNoIndex: none). Faces that were
// already degenerate are ignored.
bool moves_keep_faces_valid(const HalfEdgeBuffer& buffer, uint32_t v, const double from[3],
                            const double to[3], uint32_t skip0, uint32_t skip1);

// DECIMATE(1) of §4.3: draws up to `candidates` eligible half-edges (at most 8·candidates
// random draws), collapses the valid one with the smallest error (validity as collapse_valid's
// with `knife_edges`), each rated and placed by collapse_placement(). Returns false when no
// candidate was found or none was valid (the caller decides whether that means "stalled").
//
// Beyond the paper: with `memory`, the runners-up of one call (the valid-looking candidates
// that were not collapsed) compete again in the next call next to the fresh draws, so that
// cheap collapses found once are not forgotten. That brings the choice closer to Garland &
// Heckbert's greedy order; still deterministic for a seed. Their ratings are kept: when
// nothing but the last collapse changed the buffer since (HalfEdgeBuffer::edits()), a
// runner-up touching none of the vertices that collapse changed (p, q and the two opposite
// corners) still has exactly the rating it had and is not re-rated; others are.
struct CandidateMemory {
    static constexpr int kCapacity = 64;
    struct Entry {
        uint32_t h, p, q;
        double error;
        double target[3];
    };
    // Two rating tables used in turn: a call rates into one while the previous call's
    // runners-up are read from the other (no copying).
    Entry table[2][2 * kCapacity];
    int current = 0;                // the table the last call rated into
    uint8_t runner_up[kCapacity];   // its runners-up, best first
    int count = 0;
    uint64_t edits = 0;        // buffer.edits() right after the last collapse
    uint32_t touched[4] = {};  // the vertices that collapse changed
};
bool decimate_once(HalfEdgeBuffer& buffer, Rng& rng, int candidates, CandidateMemory* memory = nullptr,
                   KnifeEdges knife_edges = KnifeEdges::kRefuse);

// A boundary collapse removing exactly one face, used once at the end of input to land on an
// odd target count: the valid collapse p→q along a true-boundary half-edge (no partner, p not
// on P_in or P_out) with the smallest error, found by a scan of the buffer. Returns false when
// there is none (closed meshes have an even face count).
bool collapse_one_boundary_edge(HalfEdgeBuffer& buffer);

// The valid collapse with the smallest error among every eligible half-edge of the buffer,
// rated and placed by collapse_placement(), found by a scan; false when none is valid. For the
// end of input, when random draws stop finding the few valid collapses left in a small buffer.
// Only when no collapse is valid does it take the cheapest one that leaves a knife edge
// (KnifeEdges::kAllow): reaching the count asked for comes first (thin tubes, such as a
// spider's legs, cannot come down otherwise).
bool collapse_best_of_all(HalfEdgeBuffer& buffer);

}  // namespace meshstream::decimate
