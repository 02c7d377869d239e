// One edge collapse p→q (Wu & Kobbelt 2003, §4.3): which half-edges may collapse (the boundary
// rules of §4), where the merged vertex goes and what it costs (Garland & Heckbert's quadric
// error at the optimal placement), which collapses would break the mesh (the vetoes below),
// and the collapse itself. Which collapse comes next is greedy.hpp's business.
//
// Eligibility encodes the boundary rules of §4: half-edges from a boundary vertex (P_in,
// P_out, holes, non-manifold) never collapse; half-edges into a P_in vertex never collapse
// (its quadric is incomplete); half-edges into a P_out vertex may (q keeps its frozen
// position, so P_out does not move). Beyond the paper: when q is free to move (not on P_in,
// P_out, a hole or a non-manifold edge), the merged vertex goes to the minimum of Q_p + Q_q
// (Garland & Heckbert's optimal placement); a constrained q keeps the half-edge collapse.
#pragma once

#include "decimate/halfedge_buffer.hpp"

#include <cstdint>

namespace meshstream::decimate {

// A vertex in more faces than this does not move when something collapses into it: checking
// every one of its faces against a new position on each collapse would make a hub (a cone's
// apex, a disc's centre, a scanner's invalid points) cost quadratic time.
inline constexpr uint32_t kMaxMovedFaces = 32;

// Topological eligibility of half-edge h = p→q from flags alone (cheap, used when rating):
// p interior (one closed fan, not on P_in/P_out, manifold), q manifold and not on P_in.
// Beyond the paper: a true-boundary p (a hole, off P_in and P_out, one open fan) may also
// collapse along its outgoing boundary edge (twin kOpenEdge), as in Garland & Heckbert; its
// quadric holds the boundary planes added when it left P_in, which keep the hole's outline. So
// may a p where boundary loops touch (kManyFans with kOpenFans: several fans, all open): its
// quadric holds the boundary planes of every loop through it, which price moving it off any of
// them, and the link condition over all its faces keeps the edges manifold.
// With channels (attribute_store.hpp): a seam vertex p collapses only along its seam (seam_slides),
// and a seam vertex q takes any other collapse only where its corners on the edge's two faces
// agree (seam_allows).
bool seam_allows(const HalfEdgeBuffer& buffer, uint32_t h);
bool seam_slides(const HalfEdgeBuffer& buffer, uint32_t h);
inline bool collapse_eligible(const HalfEdgeBuffer& buffer, uint32_t h) {
    const Vertex& p = buffer.vertex(buffer.corner_vertex(h));
    if ((p.flags & (kInHash | kFrozen | kNonManifold)) != 0) return false;
    const bool touching = (p.flags & kManyFans) != 0;
    if (touching && (p.flags & (kOpenFans | kSeam)) != kOpenFans) return false;
    if (p.flags & kSeam) {
        const Vertex& q = buffer.vertex(buffer.corner_vertex(next_in_face(h)));
        return p.open_edges == 0 && (q.flags & (kInHash | kNonManifold)) == 0 && seam_slides(buffer, h);
    }
    if (p.open_edges == 0) {
        if (!is_half_edge(buffer.twin(h))) return false;
    } else if ((p.open_edges != 2 && !touching) || buffer.twin(h) != kOpenEdge) {
        return false;
    }
    const Vertex& q = buffer.vertex(buffer.corner_vertex(next_in_face(h)));
    return (q.flags & (kInHash | kNonManifold)) == 0 && ((q.flags & kSeam) == 0 || seam_allows(buffer, h));
}

// True when the target q of an eligible h = p→q may move (beyond the paper, as Garland &
// Heckbert's full edge collapse): q is not on P_in (its quadric is incomplete), not written
// (P_out keeps its position), not on a hole or an open edge, manifold, and in at most
// kMaxMovedFaces faces.
inline bool collapse_target_free(const HalfEdgeBuffer& buffer, uint32_t h) {
    const Vertex& q = buffer.vertex(buffer.corner_vertex(next_in_face(h)));
    return (q.flags & (kInHash | kFrozen | kNonManifold | kSeam)) == 0 && q.open_edges == 0 &&
           q.face_count <= kMaxMovedFaces;
}

// The quadric a merge of p and q minimizes: Q_p + Q_q, plus, when the buffer carries weighted
// channels, (Q_p + Q_q) / W plus the attribute error minimized over the merged vertex's values
// (AttributeStore::combined; attributes.hpp).
// Inline for the common case (no channels): every rating of a free edge sums two quadrics.
Quadric merged_quadric_with_attributes(const HalfEdgeBuffer& buffer, uint32_t p, uint32_t q);
inline Quadric merged_quadric(const HalfEdgeBuffer& buffer, uint32_t p, uint32_t q) {
    if (buffer.attributes() != nullptr) return merged_quadric_with_attributes(buffer, p, q);
    return buffer.quadric(p) + buffer.quadric(q);
}

// The quadric error of collapsing h = p→q without moving q: merged_quadric evaluated at q; when
// q's values are fixed (written or a seam vertex), the attribute error of p's quadric at q's
// position and the values q shows on h's face.
double collapse_error(const HalfEdgeBuffer& buffer, uint32_t h);

// Where an eligible collapse h = p→q puts the merged vertex, and its error. When q is free
// (collapse_target_free): the minimum of Q_p + Q_q (rounded to stored float coordinates), or,
// when that is singular, the best of p, q and their midpoint; otherwise q itself (the
// half-edge collapse of §4.3). `target` is relative to the buffer's origin. The same merge
// whichever way round when both ends are free.
struct CollapsePlacement {
    double target[3];
    double error;
};
CollapsePlacement collapse_placement(const HalfEdgeBuffer& buffer, uint32_t h);
// collapse_placement() of a merge of free ends p and q whose quadric `sum` (merged_quadric) has
// no minimum: the best of q, p and their midpoint.
CollapsePlacement singular_merge(const HalfEdgeBuffer& buffer, const Quadric& sum, uint32_t p, uint32_t q);

// A hole of three edges (beyond the paper, as meshoptimizer's simplifier lets it happen): when
// the open half-edge h = p→q lies on a hole p→q→a→p, off P_in at all three corners, its collapse
// closes the hole, making a→p (then a→q) and q→a twins; the link condition lets a pass as a
// common neighbour of p and q. Small holes shrink to three edges and then stayed: where loops
// touch at vertices (low-poly models) they kept the touching vertices from ever moving, and
// many small holes held much of a 10 % budget. Its boundary planes price the closing like any
// other collapse. `a` is kNoIndex when h is on no such hole (or h is a lone triangle's edge).
struct ClosedHole {
    uint32_t a = kNoIndex;
    uint32_t qa = kNoIndex, ap = kNoIndex;  // the open half-edges q→a and a→p
};
ClosedHole closed_hole(const HalfEdgeBuffer& buffer, uint32_t h);

// The vetoes: an eligible collapse h = p→q with the merged vertex at `target` (relative
// coordinates) is refused when
//  - the faces on the edge share their third vertex (r == s: two faces back to back);
//  - it closes a hole of three edges (closed_hole) whose faces on q→a and a→p share their third
//    vertex (they would end up back to back), or at a seam vertex (kSeam);
//  - it would collapse a tetrahedron (p and q in three faces each, the edge interior);
//  - p and q have a common neighbour besides r, s and a closed hole's third corner (the link
//    condition, Dey et al.; Hoppe's edge collapse legality): the mesh would pinch there;
//  - q is written and p has another written neighbour: the new edge may already be in the
//    output, where the link condition, which sees only in-core edges, cannot find it;
//  - a remaining face of p (or of q, when q moves) would flip, fold or degenerate
//    (moves_keep_faces_valid).
// p's faces are one fan (kManyFans is found when p leaves P_in), or several open fans
// (kOpenFans), whose faces the link condition walks all of: a face of another fan on p and q
// would have a third corner next to both.
bool shares_apex(const HalfEdgeBuffer& buffer, uint32_t h);
bool closes_hole_badly(const HalfEdgeBuffer& buffer, uint32_t h);
bool collapses_tetrahedron(const HalfEdgeBuffer& buffer, uint32_t h);
bool pinches_link(HalfEdgeBuffer& buffer, uint32_t h);
bool may_double_written_edge(const HalfEdgeBuffer& buffer, uint32_t h);
bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h, const double target[3]);
// A hint only: fetches the face records and vertex records round both ends of h (what
// collapse_valid reads), walking four chains of twins at once (both ways round p and q from
// the edge), so that their cache misses overlap instead of following each other.
void prefetch_neighbourhood(const HalfEdgeBuffer& buffer, uint32_t h);
// The same for the half-edge collapse (target: q's position).
bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h);

// True when moving vertex v from `from` to `to` (relative coordinates) flips, folds or
// degenerates none of its faces other than `skip0`/`skip1` (kNoIndex: none): each face may
// turn by at most ~84°, must still face within ~143° of the way its vertex's fan faced before
// (turns measured against each face's own normal add up over successive collapses), and must
// not become a needle or cap. Faces that were already degenerate are ignored unless they come
// out sound and facing against the fan.
bool moves_keep_faces_valid(const HalfEdgeBuffer& buffer, uint32_t v, const double from[3], const double to[3],
                            uint32_t skip0, uint32_t skip1);

// Performs the collapse p→q: removes the one or two faces on the edge, re-links their outer
// neighbours, moves p's corners to q and adds Q_p to Q_q, frees p, closes a hole of three edges
// (closed_hole: q's and a's fans walked again, HalfEdgeBuffer::classify_fans), and moves q to
// `target` (when it differs from q's position). Vertices whose open edges changed are listed for
// rating (mark_pending). Precondition: collapse_valid(buffer, h, target), and q free
// (collapse_target_free) unless target is q's position.
void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h, const double target[3]);
// The half-edge collapse (q stays). Precondition: collapse_valid(buffer, h).
void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h);

}  // namespace meshstream::decimate
