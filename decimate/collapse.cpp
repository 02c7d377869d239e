// Multiple-choice half-edge collapses (Wu & Kobbelt 2003, §4.3) with the validity tests
// that keep the in-core mesh a manifold: the link condition (Dey et al.; Hoppe's "edge
// collapse legality"), normal flip/fold and degeneracy checks as in meshoptimizer's
// simplifier and Garland & Heckbert's implementation.
#include "decimate/collapse.hpp"

#include "decimate/phase_timers.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace meshstream::decimate {
namespace {

// A remaining face may turn by at most ~84° (cos > 0.1): more is a flip or a fold.
constexpr double kMinNormalCos = 0.1;
// A moved face may point at most ~127° away from its fan's area-weighted normal before the
// move (cos > −0.6). Measured as the bound: a UV sphere (valence 500 at the poles) decimated
// to 10 % through --buffer 2000–8000 had 4 faces facing inwards without it, 0–2 tiny ones with
// it; requiring under 90° left none but cost the 1 M mesh at 1 % a seventh more RMS error
// (fans on its bumpy surface are often saddles), and −0.3 a twentieth.
constexpr double kMinFanCos = -0.6;
// |n|² / (Σ edge²)² below this is a needle or cap (0.083 for an equilateral triangle).
constexpr double kMinShapeQuality = 1e-8;
// The two faces beside a removed face become neighbours; their normals may be at most ~154°
// apart (cos > −0.9). Further is a knife edge or a fold: a gear's thin tooth whose narrow top
// strip collapses leaves its two walls back to back. Neither wall need turn much (they were
// nearly opposite across the strip already), so the per-face limits above do not see it.
constexpr double kMinWingCos = -0.9;

void sub(const double a[3], const double b[3], double out[3]) {
    out[0] = a[0] - b[0]; out[1] = a[1] - b[1]; out[2] = a[2] - b[2];
}
void cross(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

bool boundary_eligible(const HalfEdgeBuffer& buffer, uint32_t h) {
    if (buffer.twin(h) != kOpenEdge) return false;
    const Vertex& p = buffer.vertex(buffer.corner_vertex(h));
    if ((p.flags & (kInHash | kFrozen | kNonManifold)) != 0 || p.open_edges != 2) return false;
    const Vertex& q = buffer.vertex(buffer.corner_vertex(next_in_face(h)));
    return (q.flags & (kInHash | kNonManifold)) == 0;
}

}  // namespace

// Shared by writing.cpp: would moving vertex v from `from` to `to` flip, fold or degenerate
// any of its faces other than `skip0`/`skip1`?
bool moves_keep_faces_valid(const HalfEdgeBuffer& buffer, uint32_t v, const double from[3],
                            const double to[3], uint32_t skip0, uint32_t skip1) {
    // Each face may turn by at most ~84°, and must also still roughly face the way the fan did
    // before the move (its area-weighted normal, kMinFanCos): turns measured only against each
    // face's own current normal add up over successive collapses, and faces next to a sphere's
    // poles came out facing inwards through small buffers. `fan` sums the sound faces' old normals;
    // the new normals wait in `moved` (past its size, the fan is walked a second time).
    double fan[3] = {0, 0, 0}, largest_old2 = 0;
    constexpr int kMaxMoved = 32;
    double moved[kMaxMoved][3];
    int moved_count = 0;
    bool overflow = false;
    // Calls visit(n_old, n_new, was_degenerate, degenerate) for each face of v but the skipped
    // ones, until it returns false; returns whether every call returned true.
    auto each_face = [&](auto&& visit) {
        for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
            const uint32_t f = face_of(c);
            if (f == skip0 || f == skip1) continue;
            double a[3], b[3];
            buffer.position(buffer.corner_vertex(next_in_face(c)), a);
            buffer.position(buffer.corner_vertex(prev_in_face(c)), b);
            double ea[3], eb[3], ab[3], n_old[3], n_new[3];
            sub(a, b, ab);
            const double ab2 = dot(ab, ab);
            // Each shape is judged by its own edges, the old one by the old edges: judged by the
            // new, longer ones, a small sound face looked degenerate, was let through and flipped
            // (a flat disc decimated to 10 % had 26 faces upside down).
            sub(a, from, ea); sub(b, from, eb); cross(ea, eb, n_old);
            const double old_edges2 = dot(ea, ea) + dot(eb, eb) + ab2;
            sub(a, to, ea); sub(b, to, eb); cross(ea, eb, n_new);
            const double new_edges2 = dot(ea, ea) + dot(eb, eb) + ab2;
            const double old_len2 = dot(n_old, n_old), new_len2 = dot(n_new, n_new);
            const bool was_degenerate = old_len2 <= kMinShapeQuality * old_edges2 * old_edges2 || old_len2 == 0;
            const bool degenerate = new_len2 <= kMinShapeQuality * new_edges2 * new_edges2;
            if (!visit(n_old, n_new, was_degenerate, degenerate)) return false;
        }
        return true;
    };
    const bool turns_ok = each_face([&](const double* n_old, const double* n_new, bool was_degenerate, bool degenerate) {
        if (!was_degenerate) {
            if (degenerate) return false;
            // cos(turn) ≤ kMinNormalCos, without a square root.
            const double d = dot(n_old, n_new);
            if (d <= 0 || d * d <= kMinNormalCos * kMinNormalCos * dot(n_old, n_old) * dot(n_new, n_new)) return false;
            for (int i = 0; i < 3; ++i) fan[i] += n_old[i];
            largest_old2 = std::max(largest_old2, dot(n_old, n_old));
        } else if (degenerate) {
            return true;  // nothing to preserve, and it must not block the mesh
        }
        // Sound after the move (a degenerate face too: a sliver turned over must not become a
        // real face upside down): checked against the fan below.
        if (moved_count < kMaxMoved) std::copy(n_new, n_new + 3, moved[moved_count++]);
        else overflow = true;
        return true;
    });
    if (!turns_ok) return false;
    // cos(angle to the fan's normal) > kMinFanCos, without a square root. A fan whose normals
    // nearly cancel (a knife edge, a thin plate's rim) has no direction to keep: then only the
    // per-face turn applies.
    const bool fan_has_direction = dot(fan, fan) >= 0.25 * largest_old2;
    auto faces_fan = [&](const double n[3]) {
        const double d = dot(fan, n);
        return !fan_has_direction || d >= 0 || d * d < kMinFanCos * kMinFanCos * dot(fan, fan) * dot(n, n);
    };
    for (int i = 0; i < moved_count; ++i)
        if (!faces_fan(moved[i])) return false;
    // The faces past `moved`'s size, met in the same order on a second walk.
    int seen = 0;
    return !overflow || each_face([&](const double*, const double* n_new, bool was_degenerate, bool degenerate) {
        return (was_degenerate && degenerate) || ++seen <= kMaxMoved || faces_fan(n_new);
    });
}

CollapsePlacement collapse_placement(const HalfEdgeBuffer& buffer, uint32_t h) {
    const PhaseTimer timer(Phase::kRate);
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    const Quadric sum = buffer.quadric(p) + buffer.quadric(q);
    CollapsePlacement out;
    buffer.position(q, out.target);
    out.error = sum.error(out.target);
    out.moves_target = false;
    if (!collapse_target_free(buffer, h)) return out;
    // Takes y when its error is below the best so far (round-off can put the rounded optimum
    // a hair above an end point: the smaller wins).
    auto consider = [&](const double y[3]) {
        const double e = sum.error(y);
        if (e < out.error) {
            for (int i = 0; i < 3; ++i) out.target[i] = y[i];
            out.error = e;
            out.moves_target = true;
        }
    };
    double x[3];
    if (sum.minimum(x)) {
        buffer.round_position(x);
        consider(x);
        return out;
    }
    // Singular (flat or cylindrical neighbourhood): the best of p, q and the midpoint, as
    // Garland & Heckbert.
    double a[3], mid[3];
    buffer.position(p, a);
    for (int i = 0; i < 3; ++i) mid[i] = 0.5 * (a[i] + out.target[i]);
    buffer.round_position(mid);
    consider(a);
    consider(mid);
    return out;
}

bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h) {
    double to[3];
    buffer.position(buffer.corner_vertex(next_in_face(h)), to);
    return collapse_valid(buffer, h, to);
}

bool collapse_valid(HalfEdgeBuffer& buffer, uint32_t h, const double target[3], KnifeEdges knife_edges) {
    const PhaseTimer timer(Phase::kValidate);
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    const uint32_t t = buffer.twin(h);
    const bool boundary = !is_half_edge(t);
    const uint32_t r = buffer.corner_vertex(prev_in_face(h));
    const uint32_t s = boundary ? kNoIndex : buffer.corner_vertex(prev_in_face(t));
    if (r == s) return false;
    const Vertex& vp = buffer.vertex(p);
    const Vertex& vq = buffer.vertex(q);

    if (!boundary && vp.face_count == 3 && vq.face_count == 3) return false;  // tetrahedron

    // p's faces must form one fan reachable from h (a closed one for an interior edge, an
    // open one starting at h for a boundary edge): a vertex where two fans touch is not a
    // manifold vertex and must not move. Each step of a fan walk waits for the face record
    // the step before named (a cache miss: the buffer is far larger than the caches), so the
    // fans of p and q are walked both ways round at once, four chains of about half a fan
    // each, in lockstep. q's neighbours are gathered from the face records alone (no vertex
    // reads) for the link condition below; p's neighbours (and q's, when q moves) are
    // prefetched for the geometric checks.
    constexpr uint32_t kMaxRing = 48;
    uint32_t ring[2 * kMaxRing];
    uint32_t ring_size = 0;
    const bool use_ring = vq.face_count <= kMaxRing;
    double from_q[3];
    buffer.position(q, from_q);
    const bool moving_q = from_q[0] != target[0] || from_q[1] != target[1] || from_q[2] != target[2];
    // Every neighbour x of q is the next corner of a face with q→x, or else the previous
    // corner of one with x→q whose twin is no half-edge: listing prev only then keeps the ring
    // free of duplicates on a manifold fan. c is q's corner of a face.
    auto add_to_ring = [&](uint32_t c) {
        ring[ring_size++] = buffer.corner_vertex(next_in_face(c));
        if (moving_q) buffer.prefetch_vertex(ring[ring_size - 1]);  // for the check of q's faces
        if (!is_half_edge(buffer.twin(prev_in_face(c)))) ring[ring_size++] = buffer.corner_vertex(prev_in_face(c));
    };
    // Outgoing half-edges of p (and of q) reached turning one way (a: e → twin(prev(e))) and
    // the other (b: e → next(twin(e))) from h's face; a walk ends at an edge without partner
    // or where it meets the other.
    uint32_t pa = h, pb = h;
    bool pa_on = true, pb_on = !boundary;  // a boundary h is one end of p's open fan
    uint32_t count = 1;
    buffer.prefetch_vertex(buffer.corner_vertex(prev_in_face(h)));
    uint32_t qa = next_in_face(h), qb = qa;
    bool qa_on = use_ring, qb_on = use_ring;
    uint32_t q_count = 1;
    if (use_ring) add_to_ring(qa);
    // One step of a walk round q to `next` (kNoIndex: an edge without partner, where it
    // ends); both walks end where they meet, or past q's face count (not one fan: the corner
    // list below decides).
    auto step_q = [&](bool& on, uint32_t& cur, uint32_t other, uint32_t next) {
        if (next == kNoIndex) {
            on = false;
        } else if (next == other || ++q_count > vq.face_count) {
            qa_on = qb_on = false;
        } else {
            cur = next;
            add_to_ring(cur);
        }
    };
    while (pa_on || pb_on || qa_on || qb_on) {
        if (pa_on) {
            const uint32_t next = buffer.twin(prev_in_face(pa));
            if (!is_half_edge(next)) {
                if (!boundary) return false;
                pa_on = false;
            } else if (next == pb) {
                if (boundary) return false;
                pa_on = pb_on = false;
            } else {
                pa = next;
                if (++count > vp.face_count) return false;
                buffer.prefetch_vertex(buffer.corner_vertex(prev_in_face(pa)));
            }
        }
        if (pb_on) {
            const uint32_t back = buffer.twin(pb);
            if (!is_half_edge(back)) return false;  // an interior p has no edge without partner
            const uint32_t next = next_in_face(back);
            if (next == pa) {
                pa_on = pb_on = false;
            } else {
                pb = next;
                if (++count > vp.face_count) return false;
                buffer.prefetch_vertex(buffer.corner_vertex(prev_in_face(pb)));
            }
        }
        if (qa_on) {
            const uint32_t next = buffer.twin(prev_in_face(qa));
            step_q(qa_on, qa, qb, is_half_edge(next) ? next : kNoIndex);
        }
        if (qb_on) {
            const uint32_t back = buffer.twin(qb);
            step_q(qb_on, qb, qa, is_half_edge(back) ? next_in_face(back) : kNoIndex);
        }
    }
    if (count != vp.face_count) return false;
    // A tetrahedron attached to the rest only at q (q joins a second fan, so the check above,
    // which counts all of q's faces, missed it) would collapse to two faces back to back.
    if (!boundary && vp.face_count == 3 && use_ring && q_count == 3) return false;
    if (use_ring && q_count != vq.face_count) {
        // q's faces are not all in the fan around h's face (q joins two fans, which is rare):
        // gather its neighbours from its corner list instead.
        ring_size = 0;
        for (uint32_t c = vq.first_corner; c != kNoIndex; c = buffer.next_corner(c)) add_to_ring(c);
    }

    // Link condition: the common neighbours of p and q are exactly r (and s).
    auto shared = [&](uint32_t x) {
        if (x == q || x == r || x == s) return false;
        for (uint32_t i = 0; i < ring_size; ++i)
            if (ring[i] == x) return true;
        return false;
    };
    if (use_ring) {
        for (uint32_t cp = vp.first_corner; cp != kNoIndex; cp = buffer.next_corner(cp)) {
            if (shared(buffer.corner_vertex(next_in_face(cp)))) return false;
            if (!is_half_edge(buffer.twin(prev_in_face(cp))) && shared(buffer.corner_vertex(prev_in_face(cp))))
                return false;
        }
    } else {
        // A high-valence q: mark its neighbours instead of searching a list.
        const uint32_t mark = buffer.new_stamp();
        for (uint32_t cq = vq.first_corner; cq != kNoIndex; cq = buffer.next_corner(cq)) {
            buffer.stamp(buffer.corner_vertex(next_in_face(cq))) = mark;
            buffer.stamp(buffer.corner_vertex(prev_in_face(cq))) = mark;
        }
        for (uint32_t cp = vp.first_corner; cp != kNoIndex; cp = buffer.next_corner(cp)) {
            const uint32_t x = buffer.corner_vertex(next_in_face(cp));
            const uint32_t y = buffer.corner_vertex(prev_in_face(cp));
            if (x != q && x != r && x != s && buffer.stamp(x) == mark) return false;
            if (y != q && y != r && y != s && buffer.stamp(y) == mark) return false;
        }
    }

    // Into a written q: p's other written neighbours y would gain an edge q–y, which the
    // written mesh may already hold (two P_out stretches meeting, a written triangle q, y, z
    // beyond a thin strip): the link condition above sees only in-core edges, and the output
    // would get an edge with four triangles. Such collapses are refused; edges to unwritten
    // neighbours are all in core, so the link condition covers them.
    if ((vq.flags & kFrozen) != 0) {
        auto written_other = [&](uint32_t y) {
            return y != q && y != r && y != s && (buffer.vertex(y).flags & kFrozen) != 0;
        };
        for (uint32_t cp = vp.first_corner; cp != kNoIndex; cp = buffer.next_corner(cp))
            if (written_other(buffer.corner_vertex(next_in_face(cp))) ||
                written_other(buffer.corner_vertex(prev_in_face(cp))))
                return false;
    }

    // The faces beside removed face (u, v, w), where e = u→v is h or its twin, meet across w–v
    // once u and v are at the target: (w, v, x) through twin(v→w), (u, w, y) through twin(w→u).
    auto back_to_back = [&](uint32_t e) {
        const uint32_t a = buffer.twin(next_in_face(e)), b = buffer.twin(prev_in_face(e));
        if (!is_half_edge(a) || !is_half_edge(b)) return false;
        double w[3], x[3], y[3], e1[3], e2[3], na[3], nb[3];
        buffer.position(buffer.corner_vertex(a), w);
        buffer.position(buffer.corner_vertex(prev_in_face(a)), x);
        buffer.position(buffer.corner_vertex(prev_in_face(b)), y);
        sub(target, w, e1); sub(x, w, e2); cross(e1, e2, na);
        sub(w, target, e1); sub(y, target, e2); cross(e1, e2, nb);
        const double d = dot(na, nb);
        return d < 0 && d * d > kMinWingCos * kMinWingCos * dot(na, na) * dot(nb, nb);
    };
    if (knife_edges == KnifeEdges::kRefuse && (back_to_back(h) || (!boundary && back_to_back(t)))) return false;

    double from_p[3];
    buffer.position(p, from_p);
    const uint32_t skip1 = boundary ? kNoIndex : face_of(t);
    if (!moves_keep_faces_valid(buffer, p, from_p, target, face_of(h), skip1)) return false;
    return !moving_q || moves_keep_faces_valid(buffer, q, from_q, target, face_of(h), skip1);
}

void apply_collapse(HalfEdgeBuffer& buffer, uint32_t h) {
    const PhaseTimer timer(Phase::kApply);
    const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
    const uint32_t t = buffer.twin(h);
    const bool boundary = !is_half_edge(t);
    const uint32_t r = buffer.corner_vertex(prev_in_face(h));
    const uint32_t s = boundary ? kNoIndex : buffer.corner_vertex(prev_in_face(t));

    auto drop_open = [&](uint32_t e) {
        if (buffer.twin(e) == kOpenEdge) {
            --buffer.vertex(buffer.corner_vertex(e)).open_edges;
            --buffer.vertex(buffer.corner_vertex(next_in_face(e))).open_edges;
        }
    };
    // The outer neighbours across the two remaining edges of a removed face become twins.
    auto join = [&](uint32_t x, uint32_t y) {
        const bool real_x = is_half_edge(x), real_y = is_half_edge(y);
        if (real_x) buffer.set_twin(x, y);
        if (real_y) buffer.set_twin(y, x);
        if (real_x != real_y && (real_x ? y : x) == kOpenEdge) {
            const uint32_t e = real_x ? x : y;
            ++buffer.vertex(buffer.corner_vertex(e)).open_edges;
            ++buffer.vertex(buffer.corner_vertex(next_in_face(e))).open_edges;
        }
    };

    const uint32_t h1 = next_in_face(h), h2 = prev_in_face(h);
    const uint32_t o1 = buffer.twin(h1), o2 = buffer.twin(h2);
    drop_open(h);
    drop_open(h1);
    drop_open(h2);
    uint32_t u1 = kNoIndex, u2 = kNoIndex;
    if (!boundary) {
        const uint32_t t1 = next_in_face(t), t2 = prev_in_face(t);
        u1 = buffer.twin(t1);
        u2 = buffer.twin(t2);
        drop_open(t1);
        drop_open(t2);
        buffer.detach_face(face_of(t));
    }
    buffer.detach_face(face_of(h));
    join(o1, o2);
    if (!boundary) join(u1, u2);

    buffer.move_corners(p, q);
    buffer.quadric(q) += buffer.quadric(p);
    if ((buffer.vertex(q).flags & kFrozen) == 0) buffer.set_partner(q, buffer.vertex(p).pos);
    Vertex& vp = buffer.vertex(p);
    buffer.vertex(q).open_edges += vp.open_edges;
    vp.open_edges = 0;
    buffer.free_vertex(p);
    // An ear collapse can leave a vertex without faces.
    for (uint32_t v : {q, r, s}) {
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

bool decimate_once(HalfEdgeBuffer& buffer, Rng& rng, int candidates, CandidateMemory* memory, KnifeEdges knife_edges) {
    using Candidate = CandidateMemory::Entry;
    constexpr int kMaxCandidates = CandidateMemory::kCapacity;
    const int wanted = std::clamp(candidates, 1, kMaxCandidates);
    const FaceSet& live = buffer.live_faces();
    const uint64_t size = live.size();
    if (size == 0) return false;
    // Ratings go into a table; `order` sorts them by error (stable: ties keep rating order).
    Candidate local[2 * kMaxCandidates];
    Candidate* rated = memory != nullptr ? memory->table[memory->current ^ 1] : local;
    uint8_t order[2 * kMaxCandidates];
    int found = 0;
    auto insert = [&](const Candidate& c) {
        rated[found] = c;
        int i = found;
        while (i > 0 && rated[order[i - 1]].error > c.error) {
            order[i] = order[i - 1];
            --i;
        }
        order[i] = static_cast<uint8_t>(found++);
    };
    auto rate = [&](uint32_t h) {
        const CollapsePlacement placement = collapse_placement(buffer, h);
        insert(Candidate{h, buffer.corner_vertex(h), buffer.corner_vertex(next_in_face(h)), placement.error,
                         {placement.target[0], placement.target[1], placement.target[2]}});
    };
    std::optional<PhaseTimer> draw_timer(std::in_place, Phase::kDraw);
    // Remembered runners-up whose face is still alive (a reused face slot is just another
    // half-edge, rated afresh like a draw).
    int remembered = 0;
    if (memory != nullptr) {
        const bool ratings_kept = memory->edits == buffer.edits();
        auto changed = [&](uint32_t v) {
            return v == memory->touched[0] || v == memory->touched[1] || v == memory->touched[2] ||
                   v == memory->touched[3];
        };
        const Candidate* previous = memory->table[memory->current];
        for (int i = 0; i < memory->count && remembered < (wanted + 1) / 2; ++i) {
            const Candidate& c = previous[memory->runner_up[i]];
            if (!live.contains(face_of(c.h)) || !collapse_eligible(buffer, c.h)) continue;
            if (ratings_kept && buffer.corner_vertex(c.h) == c.p &&
                buffer.corner_vertex(next_in_face(c.h)) == c.q && !changed(c.p) && !changed(c.q)) {
                insert(c);
            } else {
                rate(c.h);
            }
            ++remembered;
        }
        memory->count = 0;
    }
    // Draws go in batches whose memory accesses are prefetched stage by stage (set slot →
    // half-edge → vertices and quadrics), so the random reads overlap instead of queuing:
    // the buffer is far larger than the caches. Same draws, same order as one at a time.
    uint64_t draw[kMaxCandidates];
    uint32_t half_edges[kMaxCandidates];
    for (int tries = 0; tries < 8 * wanted && found - remembered < wanted;) {
        const int batch = std::min(wanted - (found - remembered), 8 * wanted - tries);
        for (int b = 0; b < batch; ++b) {
            const uint64_t bits = rng.next();
            draw[b] = bits;
            live.prefetch(static_cast<size_t>(((bits >> 32) * size) >> 32));
        }
        for (int b = 0; b < batch; ++b) {
            const uint64_t bits = draw[b];
            const uint32_t f = live.at(static_cast<size_t>(((bits >> 32) * size) >> 32));
            half_edges[b] = half_edge(f, static_cast<uint32_t>((bits & 0xffff) % 3));
            buffer.prefetch_face(f);
        }
        for (int b = 0; b < batch; ++b) {
            buffer.prefetch_vertex(buffer.corner_vertex(half_edges[b]));
            buffer.prefetch_vertex(buffer.corner_vertex(next_in_face(half_edges[b])));
        }
        for (int b = 0; b < batch; ++b) {
            ++tries;
            const uint32_t h = half_edges[b];
            if (!collapse_eligible(buffer, h)) continue;
            rate(h);
        }
    }
    draw_timer.reset();
    for (int i = 0; i < found; ++i) {
        const Candidate& c = rated[order[i]];
        if (i > 0 && c.h == rated[order[i - 1]].h) continue;
        if (collapse_valid(buffer, c.h, c.target, knife_edges)) {
            const uint32_t t = buffer.twin(c.h);
            const uint32_t r = buffer.corner_vertex(prev_in_face(c.h));
            const uint32_t s = is_half_edge(t) ? buffer.corner_vertex(prev_in_face(t)) : kNoIndex;
            apply_collapse(buffer, c.h, c.target);
            if (memory != nullptr) {
                // The next candidates in order (not yet checked against the topology).
                memory->current ^= 1;
                for (int j = i + 1; j < found && memory->count < CandidateMemory::kCapacity; ++j)
                    if (rated[order[j]].h != rated[order[j - 1]].h) memory->runner_up[memory->count++] = order[j];
                memory->edits = buffer.edits();
                const uint32_t touched[4] = {c.p, c.q, r, s};
                std::copy(touched, touched + 4, memory->touched);
            }
            return true;
        }
    }
    return false;
}

bool collapse_best_of_all(HalfEdgeBuffer& buffer) {
    struct Candidate {
        uint32_t h;
        CollapsePlacement placement;
    };
    std::vector<Candidate> all;
    const FaceSet& live = buffer.live_faces();
    for (size_t i = 0; i < live.size(); ++i)
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(live.at(i), k);
            if (collapse_eligible(buffer, h)) all.push_back({h, collapse_placement(buffer, h)});
        }
    // Stable: ties keep buffer order, so the result is deterministic.
    std::stable_sort(all.begin(), all.end(),
                     [](const Candidate& a, const Candidate& b) { return a.placement.error < b.placement.error; });
    for (const KnifeEdges knife_edges : {KnifeEdges::kRefuse, KnifeEdges::kAllow})
        for (const Candidate& c : all)
            if (collapse_valid(buffer, c.h, c.placement.target, knife_edges)) {
                apply_collapse(buffer, c.h, c.placement.target);
                return true;
            }
    return false;
}

bool collapse_one_boundary_edge(HalfEdgeBuffer& buffer) {
    constexpr int kKeep = 16;
    struct Candidate {
        uint32_t h;
        double error;
    };
    Candidate best[kKeep];
    int found = 0;
    const FaceSet& live = buffer.live_faces();
    for (size_t i = 0; i < live.size(); ++i) {
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(live.at(i), k);
            if (!boundary_eligible(buffer, h)) continue;
            Candidate c{h, collapse_error(buffer, h)};
            if (found == kKeep && c.error >= best[kKeep - 1].error) continue;
            int j = found < kKeep ? found++ : kKeep - 1;
            while (j > 0 && best[j - 1].error > c.error) {
                best[j] = best[j - 1];
                --j;
            }
            best[j] = c;
        }
    }
    for (int i = 0; i < found; ++i) {
        if (collapse_valid(buffer, best[i].h)) {
            apply_collapse(buffer, best[i].h);
            return true;
        }
    }
    return false;
}

}  // namespace meshstream::decimate
