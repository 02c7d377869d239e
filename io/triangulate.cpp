// Polygon triangulation (see triangulate.hpp). The polygon's plane is that of its Newell normal
// (Sutherland, Sproull & Schumacker 1974; Tampieri, "Newell's Method for Computing the Plane
// Equation of a Polygon", Graphics Gems III), which is robust for non-planar and partly
// collinear polygons. Ear clipping follows Eberly, "Triangulation by Ear Clipping" (2002): only
// reflex corners can lie inside the triangle of a convex corner that is not an ear, and
// clipping an ear changes the ear status of its two neighbours only, so after the first
// classification each clip costs two ear tests.
#include "io/triangulate.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace meshstream::io {
namespace {

// Twice the signed area of triangle (a, b, c): positive when it turns counter-clockwise.
double cross(const double* a, const double* b, const double* c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

bool same_point(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1]; }

void push_triangle(std::vector<uint32_t>& triangles, uint32_t a, uint32_t b, uint32_t c) {
    triangles.push_back(a);
    triangles.push_back(b);
    triangles.push_back(c);
}

// True when the polygon, projected to (u, v) where it is counter-clockwise, turns left or goes
// straight at every corner and its edge directions wind round once, so the fan from corner 0
// covers it once. Each step turns by less than half a turn, so the directions cross the
// vertical twice per winding: at most 2 sign changes of the edges' u (a pentagram has 4). A
// quadrilateral's 4 turns add up to less than two windings, so it needs no count.
//
// Rounding to float moves a corner by up to 2^-24 of the largest coordinate M, an edge's
// components by 2^-23 M, and the cross product of edges e and f by 2^-23 M (|e| + |f|) in
// 1-norms. Turns and u within 8 times that (slack = 2^-20 M) count as straight or vertical, so
// a polygon that was convex before rounding, straight corners included, keeps the fan it has
// always had. M is found only when needed, which for most quadrilaterals is never.
bool is_convex(const float* xyz, size_t n, int u, int v) {
    double slack = -1;
    auto get_slack = [&] {
        if (slack < 0) {
            float m = 0;
            for (size_t i = 0; i < 3 * n; ++i) m = std::max(m, std::abs(xyz[i]));
            slack = double{m} * 0x1p-20;
        }
        return slack;
    };
    auto edge = [&](size_t i, double* e) {
        const float* p = xyz + 3 * i;
        const float* q = xyz + 3 * (i + 1 == n ? 0 : i + 1);
        e[0] = double{q[u]} - p[u];
        e[1] = double{q[v]} - p[v];
        return e[0] != 0 || e[1] != 0;
    };
    const bool count_flips = n > 4;
    auto u_sign = [&](const double* e) { return e[0] > get_slack() ? 1 : e[0] < -get_slack() ? -1 : 0; };
    // Zero-length edges (repeated corners) are skipped: the turn is taken between the edges
    // on either side of them. Start from the last edge (and the last with a u sign).
    double last[2] = {0, 0};
    int sign = 0;
    for (size_t i = n; i-- > 0;) {
        double e[2];
        if (!edge(i, e)) continue;
        if (last[0] == 0 && last[1] == 0) last[0] = e[0], last[1] = e[1];
        if (!count_flips || (sign = u_sign(e)) != 0) break;
    }
    if (last[0] == 0 && last[1] == 0) return true;  // all corners in one point
    int flips = 0;
    for (size_t i = 0; i < n; ++i) {
        double e[2];
        if (!edge(i, e)) continue;
        const double turn = last[0] * e[1] - last[1] * e[0];
        const double dot = last[0] * e[0] + last[1] * e[1];
        if (turn <= 0 || dot < 0) {  // not clearly a left turn of at most 90 degrees
            const double straight =
                get_slack() * (std::abs(last[0]) + std::abs(last[1]) + std::abs(e[0]) + std::abs(e[1]));
            if (turn < -straight || (turn <= straight && dot < 0)) return false;  // right turn, or back
        }
        if (count_flips) {
            const int s = u_sign(e);
            if (s != 0 && s != sign) {
                flips += sign != 0;
                sign = s;
            }
        }
        last[0] = e[0], last[1] = e[1];
    }
    return flips <= 2;
}

}  // namespace

void triangulate_polygon(std::span<const float> xyz, TriangulateScratch& s, std::vector<uint32_t>& triangles) {
    const size_t n = xyz.size() / 3;
    assert(n >= 3 && n <= UINT32_MAX);
    if (n == 3) {
        push_triangle(triangles, 0, 1, 2);
        return;
    }
    // Newell normal (twice the vector area), as the sum of the cross products of successive
    // corners taken relative to corner 0, so that far-off polygons keep their precision.
    const float* p0 = xyz.data();
    double normal[3] = {0, 0, 0};
    double d[3] = {0, 0, 0};  // corner i - corner 0
    for (size_t i = 1; i < n; ++i) {
        const float* p = p0 + 3 * i;
        const double e[3] = {double{p[0]} - p0[0], double{p[1]} - p0[1], double{p[2]} - p0[2]};
        normal[0] += d[1] * e[2] - d[2] * e[1];
        normal[1] += d[2] * e[0] - d[0] * e[2];
        normal[2] += d[0] * e[1] - d[1] * e[0];
        std::copy(e, e + 3, d);
    }
    // Project by dropping the normal's largest axis. (u, v) follow it cyclically, which makes
    // the polygon counter-clockwise when that component is positive; swapped when negative,
    // so counter-clockwise triangles in the plane have the polygon's orientation in space.
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
    int u = (axis + 1) % 3, v = (axis + 2) % 3;
    if (normal[axis] < 0) std::swap(u, v);
    if (is_convex(p0, n, u, v)) {
        size_t at = triangles.size();
        triangles.resize(at + 3 * (n - 2));
        for (uint32_t k = 1; k + 1 < n; ++k, at += 3) {
            triangles[at] = 0;
            triangles[at + 1] = k;
            triangles[at + 2] = k + 1;
        }
        return;
    }

    s.uv.resize(2 * n);
    for (size_t i = 0; i < n; ++i) {
        s.uv[2 * i] = double{p0[3 * i + u]} - p0[u];
        s.uv[2 * i + 1] = double{p0[3 * i + v]} - p0[v];
    }
    const double* uv = s.uv.data();
    const uint32_t m = static_cast<uint32_t>(n);
    s.prev.resize(n);
    s.next.resize(n);
    for (uint32_t i = 0; i < m; ++i) {
        s.prev[i] = i == 0 ? m - 1 : i - 1;
        s.next[i] = i + 1 == m ? 0 : i + 1;
    }
    s.reflex.assign(n, 0);
    s.listed.assign(n, 0);
    s.ear.assign(n, 0);
    s.reflex_list.clear();
    s.ears.clear();
    // Straight corners block ears as reflex ones do: one may be where a boundary passes
    // through the triangle.
    auto update_reflex = [&](uint32_t i) {
        s.reflex[i] = cross(uv + 2 * s.prev[i], uv + 2 * i, uv + 2 * s.next[i]) <= 0;
        if (s.reflex[i] && !s.listed[i]) {
            s.listed[i] = 1;
            s.reflex_list.push_back(i);
        }
    };
    auto is_ear = [&](uint32_t b) {
        const double* pa = uv + 2 * s.prev[b];
        const double* pb = uv + 2 * b;
        const double* pc = uv + 2 * s.next[b];
        // Straight corners are not clipped either: a zero-area triangle would do, but a
        // simple polygon always has a strictly convex ear, which leaves none.
        if (cross(pa, pb, pc) <= 0) return false;
        const double x0 = std::min({pa[0], pb[0], pc[0]}), x1 = std::max({pa[0], pb[0], pc[0]});
        const double y0 = std::min({pa[1], pb[1], pc[1]}), y1 = std::max({pa[1], pb[1], pc[1]});
        for (size_t k = 0; k < s.reflex_list.size();) {
            uint32_t r = s.reflex_list[k];
            if (!s.reflex[r]) {  // turned convex or clipped since it was listed
                s.listed[r] = 0;
                s.reflex_list[k] = s.reflex_list.back();
                s.reflex_list.pop_back();
                continue;
            }
            ++k;
            const double* p = uv + 2 * r;
            if (p[0] < x0 || p[0] > x1 || p[1] < y0 || p[1] > y1) continue;
            // A corner at a, b or c itself (a neighbour, a repeated corner, or the other end of
            // the doubled edge that joins a hole to the outline) does not block.
            if (same_point(p, pa) || same_point(p, pb) || same_point(p, pc)) continue;
            if (cross(pa, pb, p) >= 0 && cross(pb, pc, p) >= 0 && cross(pc, pa, p) >= 0) return false;
        }
        return true;
    };
    for (uint32_t i = 0; i < m; ++i) update_reflex(i);
    for (uint32_t i = m; i-- > 0;)  // pushed backwards: clipping starts at corner 0
        if ((s.ear[i] = is_ear(i))) s.ears.push_back(i);

    uint32_t remaining = m, start = 0;
    while (remaining > 3 && !s.ears.empty()) {
        const uint32_t b = s.ears.back();
        s.ears.pop_back();
        if (!s.ear[b]) continue;  // lost its ear status after it was queued
        const uint32_t a = s.prev[b], c = s.next[b];
        push_triangle(triangles, a, b, c);
        s.next[a] = c;
        s.prev[c] = a;
        s.ear[b] = s.reflex[b] = 0;
        --remaining;
        start = a;
        update_reflex(a);  // both first: each is a possible blocker of the other's ear
        update_reflex(c);
        for (uint32_t w : {c, a}) {
            bool ear = is_ear(w);
            if (ear && !s.ear[w]) s.ears.push_back(w);
            s.ear[w] = ear;
        }
    }
    // Three corners left, or no ear among more (a self-intersecting or degenerate polygon):
    // fan the rest, so that an n-gon always gives n - 2 triangles.
    for (uint32_t w = s.next[start]; s.next[w] != start; w = s.next[w]) push_triangle(triangles, start, w, s.next[w]);
}

}  // namespace meshstream::io
