// One edge collapse (Wu & Kobbelt 2003, §4.3) with Garland & Heckbert's optimal placement and
// the vetoes that keep the in-core mesh a manifold: the link condition (Dey et al.; Hoppe's
// "edge collapse legality"), normal flip/fold and degeneracy checks as in meshoptimizer's
// simplifier (hasTriangleFlip) and Garland & Heckbert's implementation.
#include "decimate/collapse.hpp"

#include "decimate/attribute_store.hpp"
#include "decimate/phase_timers.hpp"

#include <algorithm>
#include <cmath>

namespace meshstream::decimate {
namespace {

// A remaining face may turn by at most ~84° (cos > 0.1): more is a flip or a fold.
constexpr double kMinNormalCos = 0.1;
// A moved face may point at most ~143° away from its fan's area-weighted normal before the
// move (cos > −0.8): turns of up to 84° per collapse would otherwise add up and turn faces
// inside out. Tighter bounds refuse the collapses that thin tubes need (−0.6: a spider's legs
// kept their triangles while its body lost its shape, 1.4× the error of −0.8).
constexpr double kMinFanCos = -0.8;
// |n|² / (Σ edge²)² below this is a needle or cap (0.083 for an equilateral triangle).
constexpr double kMinShapeQuality = 1e-8;
// p's neighbours gathered for the link condition when q is in at most this many faces;
// beyond, each neighbour of p looks for q among its own neighbours.
constexpr uint32_t kMaxRing = 32;

void sub(const double a[3], const double b[3], double out[3]) {
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}
double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The corners around h = p→q: p, q, r (opposite h) and s (opposite the twin; kNoIndex on a
// boundary edge); on a hole of three edges p→q→a→p (closed_hole), a and the open half-edges
// q→a and a→p, which the collapse makes twins.
struct Edge {
    uint32_t p, q, r, s, t;
    bool boundary;
    ClosedHole hole;
};
Edge edge_of(const HalfEdgeBuffer& buffer, uint32_t h) {
    Edge e;
    e.p = buffer.corner_vertex(h);
    e.q = buffer.corner_vertex(next_in_face(h));
    e.r = buffer.corner_vertex(prev_in_face(h));
    e.t = buffer.twin(h);
    e.boundary = !is_half_edge(e.t);
    e.s = e.boundary ? kNoIndex : buffer.corner_vertex(prev_in_face(e.t));
    e.hole = e.t == kOpenEdge ? closed_hole(buffer, h) : ClosedHole{};
    return e;
}

}  // namespace

bool moves_keep_faces_valid(const HalfEdgeBuffer& buffer, uint32_t v, const double from[3], const double to[3],
                            uint32_t skip0, uint32_t skip1) {
    // Face (v, a, b) with e = b − a: its normal is (a − v) × e, before (v = from) and after
    // (v = to), and its squared edge lengths sum to 2·(|a − v|² + (a − v)·e + |e|²).
    // `fan` sums the sound faces' old normals; the new normals wait in `moved` (past its size,
    // the fan is walked a second time).
    double fan[3] = {0, 0, 0}, largest_old2 = 0;
    constexpr int kMaxMoved = 32;
    double moved[kMaxMoved][3];
    int moved_count = 0;
    bool overflow = false;
    // Quality bound for |n|² ≤ q·(Σ edge²)², with the factor 2 of the sum folded in.
    constexpr double kShape = 4 * kMinShapeQuality;
    struct Normals {
        double n_old[3], n_new[3], old_len2, new_len2;
        bool was_degenerate, degenerate;
    };
    // Before and after the move side by side, lane 0 and lane 1 of one vector: the same
    // operations on both in one instruction each (SSE2 on x86-64), with the results the scalar
    // arithmetic gives.
    using Pair = double __attribute__((vector_size(16)));
    const Pair from_to[3] = {{from[0], to[0]}, {from[1], to[1]}, {from[2], to[2]}};
    auto normals = [&](uint32_t c) {
        const Face& face = buffer.face(face_of(c));
        const uint32_t k = corner_of(c);
        double a[3], b[3];
        buffer.position(face.vertex[k == 2 ? 0 : k + 1], a);
        buffer.position(face.vertex[k == 0 ? 2 : k - 1], b);
        double e[3];
        sub(b, a, e);
        Pair d[3];  // a − from, a − to
        for (int i = 0; i < 3; ++i) d[i] = a[i] - from_to[i];
        const Pair n[3] = {d[1] * e[2] - d[2] * e[1], d[2] * e[0] - d[0] * e[2], d[0] * e[1] - d[1] * e[0]};
        const double e2 = dot(e, e);
        const Pair edges = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + (d[0] * e[0] + d[1] * e[1] + d[2] * e[2]) + e2;
        const Pair len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        const Pair bound = kShape * edges * edges;
        Normals out;
        for (int i = 0; i < 3; ++i) {
            out.n_old[i] = n[i][0];
            out.n_new[i] = n[i][1];
        }
        out.old_len2 = len2[0];
        out.new_len2 = len2[1];
        // Each shape is judged by its own edges, the old one by the old edges: judged by the
        // new, longer ones, a small sound face looked degenerate, was let through and flipped
        // (a flat disc decimated to 10 % had 26 faces upside down).
        out.was_degenerate = len2[0] <= bound[0] || len2[0] == 0;
        out.degenerate = len2[1] <= bound[1];
        return out;
    };
    for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        const uint32_t f = face_of(c);
        if (f == skip0 || f == skip1) continue;
        const Normals n = normals(c);
        if (!n.was_degenerate) {
            if (n.degenerate) return false;
            // cos(turn) ≤ kMinNormalCos, without a square root.
            const double d = dot(n.n_old, n.n_new);
            if (d <= 0 || d * d <= kMinNormalCos * kMinNormalCos * n.old_len2 * n.new_len2) return false;
            for (int i = 0; i < 3; ++i) fan[i] += n.n_old[i];
            largest_old2 = std::max(largest_old2, n.old_len2);
        } else if (n.degenerate) {
            continue;  // nothing to preserve, and it must not block the mesh
        }
        // Sound after the move (a degenerate face too: a sliver turned over must not become a
        // real face upside down): checked against the fan below.
        if (moved_count < kMaxMoved)
            std::copy(n.n_new, n.n_new + 3, moved[moved_count++]);
        else
            overflow = true;
    }
    // cos(angle to the fan's normal) > kMinFanCos, without a square root. A fan whose normals
    // nearly cancel (a knife edge, a thin plate's rim) has no direction to keep: then only the
    // per-face turn applies.
    const double fan2 = dot(fan, fan);
    if (fan2 < 0.25 * largest_old2) return true;
    auto faces_fan = [&](const double n[3]) {
        const double d = dot(fan, n);
        return d >= 0 || d * d < kMinFanCos * kMinFanCos * fan2 * dot(n, n);
    };
    for (int i = 0; i < moved_count; ++i)
        if (!faces_fan(moved[i])) return false;
    if (!overflow) return true;
    // The faces past `moved`'s size, met in the same order on a second walk.
    int seen = 0;
    for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        const uint32_t f = face_of(c);
        if (f == skip0 || f == skip1) continue;
        const Normals n = normals(c);
        if (n.was_degenerate && n.degenerate) continue;
        if (++seen > kMaxMoved && !faces_fan(n.n_new)) return false;
    }
    return true;
}

bool seam_allows(const HalfEdgeBuffer& buffer, uint32_t h) {
    const AttributeStore* attributes = buffer.attributes();
    return attributes == nullptr || attributes->seam_allows(buffer, h);
}

bool seam_slides(const HalfEdgeBuffer& buffer, uint32_t h) {
    const AttributeStore* attributes = buffer.attributes();
    return attributes != nullptr && attributes->slides(buffer, h);
}

Quadric merged_quadric_with_attributes(const HalfEdgeBuffer& buffer, uint32_t p, uint32_t q) {
    const Quadric sum = buffer.quadric(p) + buffer.quadric(q);
    const AttributeStore* attributes = buffer.attributes();
    if (!attributes->weighted()) return sum;
    return AttributeStore::combined(sum, attributes->merged_reduced(buffer, p, q));
}

namespace {

// The error of h = p→q when q keeps its position and values (written, or a seam vertex): the
// geometric error at q plus p's attribute error at q with the values q shows on h's face; for a
// seam vertex p sliding along its seam, plus how far off the seam's line p lay
// (AttributeStore::slide_error: p's quadric mixes the seam's two sides).
double fixed_error(const HalfEdgeBuffer& buffer, const AttributeStore& attributes, uint32_t h) {
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    const Quadric sum = buffer.quadric(p) + buffer.quadric(q);
    double x[3];
    buffer.position(q, x);
    if (buffer.vertex(p).flags & kSeam) {
        double geometric = std::max(0.0, sum.error(x)), attribute = 0;
        attributes.slide_error(buffer, h, geometric, attribute);
        return attributes.weighted() ? AttributeStore::combined_error(sum, geometric, attribute) : geometric;
    }
    return AttributeStore::combined_error(sum, sum.error(x),
                                          attributes.error(buffer, p, x, attributes.shown(buffer, next_in_face(h))));
}

// q keeps its values (written, or a seam vertex) and weighs them, or p slides along a seam (then
// q is a seam vertex too: neither moves).
bool values_fixed(const HalfEdgeBuffer& buffer, uint32_t p, uint32_t q) {
    const AttributeStore* attributes = buffer.attributes();
    if (attributes == nullptr) return false;
    if (buffer.vertex(p).flags & kSeam) return true;
    return attributes->weighted() && (buffer.vertex(q).flags & (kSeam | kFrozen)) != 0;
}

}  // namespace

double collapse_error(const HalfEdgeBuffer& buffer, uint32_t h) {
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    if (values_fixed(buffer, p, q)) return fixed_error(buffer, *buffer.attributes(), h);
    double x[3];
    buffer.position(q, x);
    return merged_quadric(buffer, p, q).error(x);
}

CollapsePlacement collapse_placement(const HalfEdgeBuffer& buffer, uint32_t h) {
    const PhaseTimer timer(Phase::kRate);
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    CollapsePlacement out;
    buffer.position(q, out.target);
    if (values_fixed(buffer, p, q)) {  // q does not move either (collapse_target_free)
        out.error = fixed_error(buffer, *buffer.attributes(), h);
        return out;
    }
    const Quadric sum = merged_quadric(buffer, p, q);
    out.error = sum.error(out.target);
    if (!collapse_target_free(buffer, h)) return out;
    double x[3];
    if (sum.minimum(x)) {
        buffer.round_position(x);
        // Round-off can put the rounded optimum a hair above q: the smaller wins.
        const double e = sum.error(x);
        if (e < out.error) {
            for (int i = 0; i < 3; ++i) out.target[i] = x[i];
            out.error = e;
        }
        return out;
    }
    return singular_merge(buffer, sum, p, q);
}

CollapsePlacement singular_merge(const HalfEdgeBuffer& buffer, const Quadric& sum, uint32_t p, uint32_t q) {
    // Flat or cylindrical neighbourhood: the best of q, p and the midpoint, as Garland &
    // Heckbert; a later one is taken only when its error is smaller.
    CollapsePlacement out;
    buffer.position(q, out.target);
    out.error = sum.error(out.target);
    auto consider = [&](const double y[3]) {
        const double e = sum.error(y);
        if (e < out.error) {
            for (int i = 0; i < 3; ++i) out.target[i] = y[i];
            out.error = e;
        }
    };
    double a[3], mid[3];
    buffer.position(p, a);
    for (int i = 0; i < 3; ++i) mid[i] = 0.5 * (a[i] + out.target[i]);
    buffer.round_position(mid);
    consider(a);
    consider(mid);
    return out;
}

namespace {

bool shares_apex(const Edge& e) { return e.r == e.s; }

bool collapses_tetrahedron(const HalfEdgeBuffer& buffer, const Edge& e) {
    // p in three faces round an interior edge: q, r and s are all its neighbours, and its third
    // face (p, r, s) becomes (q, r, s). When the face across r–s is (q, s, r) already, p, q, r
    // and s bound a tetrahedron (alone, or hanging from the rest at q), which would collapse to
    // two faces back to back.
    if (e.boundary || buffer.vertex(e.p).face_count != 3) return false;
    for (uint32_t c = buffer.vertex(e.p).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        const uint32_t rs = next_in_face(c);  // the edge opposite p in this face
        const uint32_t a = buffer.corner_vertex(rs), b = buffer.corner_vertex(prev_in_face(c));
        if (a == e.q || b == e.q) continue;  // a face on the edge
        const uint32_t across = buffer.twin(rs);
        return is_half_edge(across) && buffer.corner_vertex(prev_in_face(across)) == e.q;
    }
    return false;
}

bool pinches_link(HalfEdgeBuffer& buffer, const Edge& e) {
    // The third corner of a hole of three edges is a common neighbour the collapse may keep: the
    // edges p–a and q–a become one, with a face on each side (closes_hole_badly checks them).
    auto other = [&](uint32_t x) { return x != e.p && x != e.q && x != e.r && x != e.s && x != e.hole.a; };
    const Vertex& vp = buffer.vertex(e.p);
    const Vertex& vq = buffer.vertex(e.q);
    if (vq.face_count <= kMaxRing) {
        // q's neighbours marked (each corner names two; repeats do no harm), p's looked up. The
        // two corner lists are walked in step, as each is a chain of cache misses and the two
        // chains overlap: p's neighbours met before q's list ends wait in `early`.
        const uint32_t mark = buffer.new_mark();
        uint32_t early[2 * kMaxRing];
        uint32_t count = 0;
        uint32_t a = vq.first_corner, b = vp.first_corner;
        auto neighbours = [&](uint32_t c, uint32_t& x, uint32_t& y) {
            const Face& face = buffer.face(face_of(c));
            const uint32_t k = corner_of(c);
            x = face.vertex[k == 2 ? 0 : k + 1];
            y = face.vertex[k == 0 ? 2 : k - 1];
            return face.next[k];
        };
        uint32_t x, y;
        while (a != kNoIndex) {
            a = neighbours(a, x, y);
            buffer.mark(x) = mark;
            buffer.mark(y) = mark;
            if (b == kNoIndex) continue;
            b = neighbours(b, early[count], early[count + 1]);
            count += 2;
        }
        for (uint32_t i = 0; i < count; ++i)
            if (buffer.mark(early[i]) == mark && other(early[i])) return true;
        while (b != kNoIndex) {
            b = neighbours(b, x, y);
            if ((buffer.mark(x) == mark && other(x)) || (buffer.mark(y) == mark && other(y))) return true;
        }
        return false;
    }
    // A hub q: each neighbour x of p looks for q among its own neighbours, so the cost stays
    // with p's fan however many faces q has.
    auto next_to_q = [&](uint32_t x) {
        for (uint32_t c = buffer.vertex(x).first_corner; c != kNoIndex; c = buffer.next_corner(c))
            if (buffer.corner_vertex(next_in_face(c)) == e.q || buffer.corner_vertex(prev_in_face(c)) == e.q)
                return true;
        return false;
    };
    for (uint32_t c = vp.first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        const uint32_t x = buffer.corner_vertex(next_in_face(c)), y = buffer.corner_vertex(prev_in_face(c));
        if ((other(x) && next_to_q(x)) || (other(y) && next_to_q(y))) return true;
    }
    return false;
}

bool closes_hole_badly(const HalfEdgeBuffer& buffer, const Edge& e) {
    // The faces on q→a and a→p end up back to back when they share their third corner (a
    // tetrahedron open at p, q, a would fold into two faces); and a seam corner (attribute_store.hpp)
    // would join corners across the new edge whose values were never compared.
    if (e.hole.a == kNoIndex) return false;
    const uint32_t x = buffer.corner_vertex(prev_in_face(e.hole.qa)), y = buffer.corner_vertex(prev_in_face(e.hole.ap));
    if (x == y) return true;
    return ((buffer.vertex(e.p).flags | buffer.vertex(e.q).flags | buffer.vertex(e.hole.a).flags) & kSeam) != 0;
}

bool may_double_written_edge(const HalfEdgeBuffer& buffer, const Edge& e) {
    // Into a written q: p's other written neighbours y would gain an edge q–y, which the
    // written mesh may already hold (two P_out stretches meeting, a written triangle q, y, z
    // beyond a thin strip); the output would get an edge with four triangles. Edges to
    // unwritten neighbours are all in core, so the link condition covers them.
    if ((buffer.vertex(e.q).flags & kFrozen) == 0) return false;
    auto written_other = [&](uint32_t y) {
        return y != e.q && y != e.r && y != e.s && (buffer.vertex(y).flags & kFrozen) != 0;
    };
    for (uint32_t c = buffer.vertex(e.p).first_corner; c != kNoIndex; c = buffer.next_corner(c))
        if (written_other(buffer.corner_vertex(next_in_face(c))) ||
            written_other(buffer.corner_vertex(prev_in_face(c))))
            return true;
    return false;
}

}  // namespace

ClosedHole closed_hole(const HalfEdgeBuffer& buffer, uint32_t h) {
    // An open half-edge q→a out of q and an open a→p out of a: the three open half-edges form a
    // cycle. Searched in the corner lists, not by walking fans: where loops touch at q or a, the
    // cycle passes from one fan to another there. a = r is the face of h itself (a lone
    // triangle), no hole.
    ClosedHole out;
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    const uint32_t r = buffer.corner_vertex(prev_in_face(h));
    for (uint32_t c = buffer.vertex(q).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        if (buffer.twin(c) != kOpenEdge) continue;
        const uint32_t a = buffer.corner_vertex(next_in_face(c));
        // a's open edges must be final: off P_in, and manifold (its fans are known).
        if (a == r || a == p || (buffer.vertex(a).flags & (kInHash | kNonManifold)) != 0) continue;
        for (uint32_t d = buffer.vertex(a).first_corner; d != kNoIndex; d = buffer.next_corner(d))
            if (buffer.twin(d) == kOpenEdge && buffer.corner_vertex(next_in_face(d)) == p) {
                out.a = a;
                out.qa = c;
                out.ap = d;
                return out;
            }
    }
    return out;
}

bool closes_hole_badly(const HalfEdgeBuffer& buffer, uint32_t h) { return closes_hole_badly(buffer, edge_of(buffer, h)); }
bool shares_apex(const HalfEdgeBuffer& buffer, uint32_t h) { return shares_apex(edge_of(buffer, h)); }
bool collapses_tetrahedron(const HalfEdgeBuffer& buffer, uint32_t h) {
    return collapses_tetrahedron(buffer, edge_of(buffer, h));
}
bool pinches_link(HalfEdgeBuffer& buffer, uint32_t h) { return pinches_link(buffer, edge_of(buffer, h)); }
bool may_double_written_edge(const HalfEdgeBuffer& buffer, uint32_t h) {
    return may_double_written_edge(buffer, edge_of(buffer, h));
}

void prefetch_neighbourhood(const HalfEdgeBuffer& buffer, uint32_t h) {
    // Round p: from h = p→q one way (the half-edge into p in each face, then its twin), from
    // h's twin q→p the other way (the half-edge out of p after it, then its twin); the same
    // round q from h's twin and h. A chain ends at an edge without a twin.
    const uint32_t t = buffer.twin(h);
    if (!is_half_edge(t)) return;
    constexpr int kSteps = 4;  // each way: a fan of up to 10 faces (more are walked by the checks)
    // Each chain's half-edge ends at (into) or starts at (out of) its vertex.
    uint32_t into[2] = {prev_in_face(h), prev_in_face(t)};     // x→p, x→q
    uint32_t out_of[2] = {next_in_face(t), next_in_face(h)};  // p→x, q→x
    for (int step = 0; step < kSteps; ++step) {
        bool any = false;
        for (int i = 0; i < 2; ++i) {
            if (into[i] != kNoIndex) {
                const uint32_t w = buffer.twin(into[i]);  // the same edge from the vertex
                if (is_half_edge(w)) {
                    into[i] = prev_in_face(w);  // from the next neighbour round
                    buffer.prefetch_vertex(buffer.corner_vertex(into[i]));
                    any = true;
                } else {
                    into[i] = kNoIndex;
                }
            }
            if (out_of[i] != kNoIndex) {
                const uint32_t w = buffer.twin(out_of[i]);  // the same edge into the vertex
                if (is_half_edge(w)) {
                    buffer.prefetch_vertex(buffer.corner_vertex(prev_in_face(w)));  // the next neighbour
                    out_of[i] = next_in_face(w);
                    any = true;
                } else {
                    out_of[i] = kNoIndex;
                }
            }
        }
        if (!any) return;
    }
}

bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h) {
    double to[3];
    buffer.position(buffer.corner_vertex(next_in_face(h)), to);
    return collapse_valid(buffer, h, to);
}

bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h, const double target[3]) {
    const PhaseTimer timer(Phase::kValidate);
    const Edge e = edge_of(buffer, h);
    if (shares_apex(e) || collapses_tetrahedron(buffer, e) || closes_hole_badly(buffer, e) || pinches_link(buffer, e) ||
        may_double_written_edge(buffer, e))
        return false;
    const uint32_t skip1 = e.boundary ? kNoIndex : face_of(e.t);
    double from_p[3], from_q[3];
    buffer.position(e.p, from_p);
    buffer.position(e.q, from_q);
    if (!moves_keep_faces_valid(buffer, e.p, from_p, target, face_of(h), skip1)) return false;
    const bool moving_q = from_q[0] != target[0] || from_q[1] != target[1] || from_q[2] != target[2];
    return !moving_q || moves_keep_faces_valid(buffer, e.q, from_q, target, face_of(h), skip1);
}

void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h) {
    const PhaseTimer timer(Phase::kApply);
    const Edge e = edge_of(buffer, h);
    // A vertex whose open edges change has other collapses now: rated again.
    auto opened = [&](uint32_t x, int change) {
        buffer.vertex(x).open_edges += change;
        buffer.mark_pending(x);
    };
    auto drop_open = [&](uint32_t x) {
        if (buffer.twin(x) == kOpenEdge) {
            opened(buffer.corner_vertex(x), -1);
            opened(buffer.corner_vertex(next_in_face(x)), -1);
        }
    };
    // The outer neighbours across the two remaining edges of a removed face become twins.
    auto join = [&](uint32_t x, uint32_t y) {
        const bool real_x = is_half_edge(x), real_y = is_half_edge(y);
        if (real_x) buffer.set_twin(x, y);
        if (real_y) buffer.set_twin(y, x);
        if (real_x != real_y && (real_x ? y : x) == kOpenEdge) {
            const uint32_t z = real_x ? x : y;
            opened(buffer.corner_vertex(z), +1);
            opened(buffer.corner_vertex(next_in_face(z)), +1);
        }
    };

    if (AttributeStore* attributes = buffer.attributes()) attributes->merge(buffer, h);
    const uint32_t h1 = next_in_face(h), h2 = prev_in_face(h);
    const uint32_t o1 = buffer.twin(h1), o2 = buffer.twin(h2);
    drop_open(h);
    drop_open(h1);
    drop_open(h2);
    uint32_t u1 = kNoIndex, u2 = kNoIndex;
    if (!e.boundary) {
        const uint32_t t1 = next_in_face(e.t), t2 = prev_in_face(e.t);
        u1 = buffer.twin(t1);
        u2 = buffer.twin(t2);
        drop_open(t1);
        drop_open(t2);
        buffer.detach_face(face_of(e.t));
    }
    buffer.detach_face(face_of(h));
    join(o1, o2);
    if (!e.boundary) join(u1, u2);

    // Boundary loops that touched at p (all its fans open: collapse_eligible) touch at q now. q,
    // on one of them, was in one open fan, or in several with or without kOpenFans, which holds.
    uint16_t& q_flags = buffer.vertex(e.q).flags;
    if ((buffer.vertex(e.p).flags & kManyFans) && (q_flags & kManyFans) == 0) q_flags |= kManyFans | kOpenFans;
    // A merged vertex is at full resolution only when both ends were (the seam pass): a seam
    // vertex merged into its decimated neighbour is gone, and the neighbour stays as it was.
    if ((buffer.vertex(e.p).flags & kFullResolution) == 0) q_flags &= ~kFullResolution;
    buffer.move_corners(e.p, e.q);
    buffer.quadric(e.q) += buffer.quadric(e.p);
    if ((buffer.vertex(e.q).flags & kFrozen) == 0) buffer.set_partner(e.q, buffer.vertex(e.p).pos);
    Vertex& vp = buffer.vertex(e.p);
    buffer.vertex(e.q).open_edges += vp.open_edges;
    vp.open_edges = 0;
    buffer.free_vertex(e.p);
    if (e.hole.a != kNoIndex) {
        // The hole p→q→a closes: a→p is a→q now, the twin of q→a. q and a may have gained a
        // closed fan, or lost one of several: their fans are walked again.
        buffer.set_twin(e.hole.qa, e.hole.ap);
        buffer.set_twin(e.hole.ap, e.hole.qa);
        opened(e.q, -2);
        opened(e.hole.a, -2);
        buffer.classify_fans(e.q);
        buffer.classify_fans(e.hole.a);
    }
    // An ear collapse can leave a vertex without faces.
    for (uint32_t v : {e.q, e.r, e.s}) {
        if (v == kNoIndex) continue;
        const Vertex& x = buffer.vertex(v);
        if ((x.flags & kAlive) && x.face_count == 0 && (x.flags & kInHash) == 0) buffer.free_vertex(v);
    }
}

void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h, const double target[3]) {
    const uint32_t q = buffer.corner_vertex(next_in_face(h));
    double at[3];
    buffer.position(q, at);
    apply_collapse(buffer, h);
    // Only a real move is stored: a float coordinate far smaller than the origin's (4.8e-17
    // beside an origin of 0.5) does not survive the trip through relative doubles, so storing
    // q's own position back changed it, even for a written q, whose triangles then no longer
    // met (zero-width cracks in a closed cylinder decimated through a small buffer).
    if (at[0] != target[0] || at[1] != target[1] || at[2] != target[2]) buffer.set_position(q, target);
}

}  // namespace meshstream::decimate
