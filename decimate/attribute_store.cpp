// Per-vertex and per-face channels of the in-core mesh, and the seam rules.
#include "decimate/attribute_store.hpp"

#include "io/error.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace meshstream::decimate {
namespace {

// Re-expresses a quadric given in y = x − a in y' = x − a' with t = a' − a: Q(y' + t) has
// b + A t and c + 2 bᵀt + tᵀA t.
inline Quadric translated(Quadric a, const double t[3]) {
    const double at[3] = {a.a00 * t[0] + a.a01 * t[1] + a.a02 * t[2], a.a01 * t[0] + a.a11 * t[1] + a.a12 * t[2],
                          a.a02 * t[0] + a.a12 * t[1] + a.a22 * t[2]};
    a.c += 2 * (a.b0 * t[0] + a.b1 * t[1] + a.b2 * t[2]) + (at[0] * t[0] + at[1] * t[1] + at[2] * t[2]);
    a.b0 += at[0];
    a.b1 += at[1];
    a.b2 += at[2];
    return a;
}

// Adds a whole attribute quadric q (doubles, or another stored one), re-expressed with t as above
// (its values G·(y' + t) + D have D + G·t), to one stored in float.
template <typename T>
void add_translated(float* stored, const T* q, int m, const double t[3]) {
    const Quadric a = translated(AttributeQuadric::part(q), t);
    const double part[10] = {a.a00, a.a01, a.a02, a.a11, a.a12, a.a22, a.b0, a.b1, a.b2, a.c};
    for (int i = 0; i < 10; ++i) stored[i] = float(double(stored[i]) + part[i]);
    stored[10] = float(double(stored[10]) + double(q[10]));
    for (int j = 0; j < m; ++j) {
        const T* g = q + 11 + 4 * j;
        float* out = stored + 11 + 4 * j;
        for (int i = 0; i < 3; ++i) out[i] = float(double(out[i]) + double(g[i]));
        out[3] = float(double(out[3]) + (double(g[3]) + (double(g[0]) * t[0] + double(g[1]) * t[1] +
                                                         double(g[2]) * t[2])));
    }
}

}  // namespace

AttributeStore::AttributeStore(const AttributeLayout& layout, size_t triangle_capacity)
    : layout_(layout),
      m_(layout.size()),
      // Whole 64-byte lines, so that a record costs as few cache misses as its size allows.
      stride_((AttributeQuadric::size(layout.size()) + 3 + size_t(layout.size()) + 15) / 16 * 16),
      value_offset_(AttributeQuadric::size(layout.size()) + 3),
      face_scalar_count_(layout.face_scalar_count()) {
    if (m_ > kMaxAttributeComponents)
        throw io::OptionError(io::Setting::kDrop, std::to_string(m_) + " attribute values per corner, more than the " +
                                                      std::to_string(kMaxAttributeComponents) +
                                                      " the decimator carries: add some to " +
                                                      io::mention(io::Setting::kDrop));
    const size_t vertices = 3 * triangle_capacity + 3;
    records_ = raw_array<float>(vertices * stride_);
    ranges_ = raw_array<float>(std::max<size_t>(1, 2 * vertices * size_t(m_)));
    if (layout.channels().material) {
        vertex_material_ = raw_array<uint32_t>(vertices);
        materials_ = raw_array<uint32_t>(triangle_capacity);
    }
    corners_ = raw_array<float>(std::max<size_t>(1, 3 * triangle_capacity * size_t(m_)));
    face_scalars_ = raw_array<double>(std::max<size_t>(1, triangle_capacity * face_scalar_count_));
}

size_t AttributeStore::reserved_bytes(const AttributeLayout& layout, size_t triangle_capacity) {
    const size_t m = size_t(layout.size()), vertices = 3 * triangle_capacity + 3;
    const bool material = layout.channels().material;
    const size_t stride = (AttributeQuadric::size(layout.size()) + 3 + m + 15) / 16 * 16;
    return vertices * (4 * stride + 8 * m + (material ? 4 : 0)) +
           triangle_capacity * (12 * m + (material ? 4 : 0) + 8 * layout.face_scalar_count());
}

void AttributeStore::sanitize(float* values, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(values[i])) {
            values[i] = 0;
            ++non_finite_;
        }
}

void AttributeStore::reference(const HalfEdgeBuffer& buffer, uint32_t v, double r[3]) const {
    const float* ref = record(v) + AttributeQuadric::size(m_);
    for (int i = 0; i < 3; ++i) r[i] = double(ref[i]) - buffer.origin(i);
}

void AttributeStore::add_quadric(const HalfEdgeBuffer& buffer, uint32_t v, const double* q) {
    double r[3];
    reference(buffer, v, r);  // from x to x − r
    add_translated(record(v), q, m_, r);
}

void AttributeStore::init_vertex(HalfEdgeBuffer& buffer, uint32_t v, const float* value, uint32_t material) {
    Vertex& x = buffer.vertex(v);
    x.flags |= kHasValues;
    float* q = record(v);
    const size_t n = AttributeQuadric::size(m_);
    std::fill_n(q, n, 0.0f);
    std::copy_n(x.pos, 3, q + n);  // the reference point: the input position
    std::copy_n(value, m_, vertex_value(v));
    std::copy_n(value, m_, range_lo(v));
    std::copy_n(value, m_, range_hi(v));
    if (vertex_material_) vertex_material_[v] = material;
}

void AttributeStore::ensure_vertex(HalfEdgeBuffer& buffer, uint32_t v, const float* value, uint32_t material) {
    if ((buffer.vertex(v).flags & kHasValues) == 0) init_vertex(buffer, v, value, material);
}

void AttributeStore::make_seam(HalfEdgeBuffer& buffer, uint32_t v) {
    // Its corners so far showed the vertex's value: now each keeps its own.
    Vertex& x = buffer.vertex(v);
    for (uint32_t c = x.first_corner; c != kNoIndex; c = buffer.next_corner(c))
        std::copy_n(vertex_value(v), m_, corner_value(c));
    x.flags |= kSeam;
    ++seam_vertices_;
}

void AttributeStore::add_face(HalfEdgeBuffer& buffer, uint32_t f, const float* corners, uint32_t material,
                              const double* face_scalars) {
    const size_t m = size_t(m_);
    if (materials_) materials_[f] = material;
    std::copy_n(face_scalars, face_scalar_count_, &face_scalars_[f * face_scalar_count_]);
    uint32_t v[3];
    double p[3][3];
    for (uint32_t k = 0; k < 3; ++k) {
        v[k] = buffer.corner_vertex(half_edge(f, k));
        buffer.position(v[k], p[k]);
        const float* value = corners + k * m;
        const uint16_t flags = buffer.vertex(v[k]).flags;
        if ((flags & kHasValues) == 0) {
            init_vertex(buffer, v[k], value, material);
        } else if ((flags & kSeam) == 0 && ((vertex_material_ && vertex_material_[v[k]] != material) ||
                                            !same_values(vertex_value(v[k]), value))) {
            make_seam(buffer, v[k]);  // this face's corner is linked already: overwritten below
        }
        if (buffer.vertex(v[k]).flags & kSeam) std::copy_n(value, m, corner_value(half_edge(f, k)));
    }
    if (m == 0) return;
    double q[AttributeQuadric::size(kMaxAttributeComponents)];
    AttributeQuadric::from_triangle(q, p[0], p[1], p[2], corners, corners + m, corners + 2 * m, m_, omega());
    for (uint32_t k = 0; k < 3; ++k) add_quadric(buffer, v[k], q);
}

bool AttributeStore::seam_allows(const HalfEdgeBuffer& buffer, uint32_t h) const {
    const uint32_t q_corner = next_in_face(h);
    const uint32_t q = buffer.corner_vertex(q_corner);
    if ((buffer.vertex(q).flags & kSeam) == 0) return true;
    const uint32_t t = buffer.twin(h);
    if (!is_half_edge(t)) return true;  // one face on the edge: one side
    // t runs q→p: its corner is q's on the other face.
    return material(face_of(h)) == material(face_of(t)) &&
           same_values(corner_value(q_corner), corner_value(t));
}

bool AttributeStore::slides(const HalfEdgeBuffer& buffer, uint32_t h) const {
    const uint32_t t = buffer.twin(h);
    const uint32_t q = buffer.corner_vertex(next_in_face(h));
    if (!is_half_edge(t) || (buffer.vertex(q).flags & kSeam) == 0) return false;
    // Along the seam at both ends: t runs q→p, so p's corner on t's face is next_in_face(t), q's is t.
    if (same_wedge(h, next_in_face(t)) || same_wedge(next_in_face(h), t)) return false;
    // Round p's fan (c → p's corner on the face across the edge into c): two changes of wedge.
    int changes = 0;
    uint32_t c = h;
    for (uint32_t steps = 0;; ++steps) {
        const uint32_t across = buffer.twin(prev_in_face(c));
        if (!is_half_edge(across) || steps > buffer.vertex(buffer.corner_vertex(h)).face_count) return false;
        changes += !same_wedge(c, across);
        c = across;
        if (c == h) break;
    }
    return changes == 2;
}

void AttributeStore::slide_error(const HalfEdgeBuffer& buffer, uint32_t h, double& geometric, double& attribute) const {
    // The other seam edge at p: crossing the edge into corner c (from w to p) changes wedge, w ≠ q.
    const uint32_t q_corner = next_in_face(h);
    uint32_t r_side[2] = {kNoIndex, kNoIndex};  // r's corners on p's side A (h's wedge) and side B
    double side_area[2] = {0, 0};
    double pp[3], pq[3], pr[3] = {0, 0, 0};
    buffer.position(buffer.corner_vertex(h), pp);
    buffer.position(buffer.corner_vertex(q_corner), pq);
    uint32_t c = h;
    do {
        const uint32_t into = prev_in_face(c), across = buffer.twin(into);
        const uint32_t w = buffer.corner_vertex(into);
        {
            double a[3], b[3], e1[3], e2[3];
            buffer.position(buffer.corner_vertex(next_in_face(c)), a);
            buffer.position(w, b);
            for (int i = 0; i < 3; ++i) e1[i] = a[i] - pp[i], e2[i] = b[i] - pp[i];
            const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                 e1[0] * e2[1] - e1[1] * e2[0]};
            side_area[same_wedge(c, h) ? 0 : 1] += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        }
        if (!same_wedge(c, across) && w != buffer.corner_vertex(q_corner)) {
            buffer.position(w, pr);
            // w's corner on c's face is `into`; on the face across, the corner after `across`.
            const bool c_is_a = same_wedge(c, h);
            r_side[c_is_a ? 0 : 1] = into;
            r_side[c_is_a ? 1 : 0] = next_in_face(across);
        }
        c = across;
    } while (c != h);
    if (r_side[0] == kNoIndex) return;  // no other seam edge (slides() rules that out)
    // Position: p's distance² from the line r–q, weighted by |r − q|.
    double d[3], e[3];
    for (int i = 0; i < 3; ++i) d[i] = pq[i] - pr[i], e[i] = pp[i] - pr[i];
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    const double s = dd > 0 ? std::clamp((e[0] * d[0] + e[1] * d[1] + e[2] * d[2]) / dd, 0.0, 1.0) : 0.0;
    double off2 = 0;
    for (int i = 0; i < 3; ++i) off2 += (e[i] - s * d[i]) * (e[i] - s * d[i]);
    geometric += off2 * std::sqrt(dd);
    // Values, per side: p's against r's and q's interpolated at p's place along the line.
    const uint32_t q_side[2] = {q_corner, buffer.twin(h)};
    const uint32_t p_side[2] = {h, next_in_face(buffer.twin(h))};
    const double* w = omega();
    for (int k = 0; k < 2; ++k) {
        const float* vp = corner_value(p_side[k]);
        const float* vq = shown(buffer, q_side[k]);
        const float* vr = shown(buffer, r_side[k]);
        double dev = 0;
        for (int j = 0; j < m_; ++j) {
            const double x = vp[j] - ((1 - s) * vr[j] + s * vq[j]);
            dev += w[j] * x * x;
        }
        attribute += side_area[k] * dev;
    }
}

void AttributeStore::merge(HalfEdgeBuffer& buffer, uint32_t h) {
    const uint32_t p = buffer.corner_vertex(h), q_corner = next_in_face(h), q = buffer.corner_vertex(q_corner);
    if (buffer.vertex(q).flags & kSeam) {
        // p's corners join q on their side of the seam: they show q's value there (a p off the
        // seam has one side, h's; a sliding p has two, h's and its twin's).
        const bool slide = (buffer.vertex(p).flags & kSeam) != 0;
        float side_a[kMaxAttributeComponents], side_b[kMaxAttributeComponents], wedge_a[kMaxAttributeComponents];
        std::copy_n(corner_value(q_corner), m_, side_a);
        if (slide) {
            std::copy_n(corner_value(buffer.twin(h)), m_, side_b);
            std::copy_n(corner_value(h), m_, wedge_a);
        }
        const uint32_t material_a = material(face_of(h));
        for (uint32_t c = buffer.vertex(p).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
            const bool on_a = !slide || (material(face_of(c)) == material_a &&
                                         same_values(corner_value(c), wedge_a));
            std::copy_n(on_a ? side_a : side_b, m_, corner_value(c));
        }
    }
    // p's quadric, relative to p's reference point, into q's.
    double rp[3], rq[3];
    reference(buffer, p, rp);
    reference(buffer, q, rq);
    const double t[3] = {rq[0] - rp[0], rq[1] - rp[1], rq[2] - rp[2]};
    add_translated(record(q), record(p), m_, t);
    float* lo = range_lo(q);
    float* hi = range_hi(q);
    for (int j = 0; j < m_; ++j) lo[j] = std::min(lo[j], range_lo(p)[j]), hi[j] = std::max(hi[j], range_hi(p)[j]);
}

void AttributeStore::settle(const HalfEdgeBuffer& buffer, uint32_t v) {
    const Vertex& x = buffer.vertex(v);
    if ((x.flags & (kSeam | kHasPartner)) != kHasPartner || m_ == 0) return;
    double at[3], r[3];
    buffer.position(v, at);
    reference(buffer, v, r);
    for (int i = 0; i < 3; ++i) at[i] -= r[i];
    double q[AttributeQuadric::size(kMaxAttributeComponents)];
    local_quadric(v, q);
    float out[kMaxAttributeComponents];
    AttributeQuadric::values(q, m_, at, vertex_value(v), out);
    // The interpolations' mean extrapolates gradients to where the vertex moved, and overshoots
    // next to a sharp change (a halo of colours the mesh never had): each value stays within the
    // range of the input values the vertex stands for.
    const float* lo = &ranges_[2 * size_t(v) * m_];
    const float* hi = lo + m_;
    for (int j = 0; j < m_; ++j) vertex_value(v)[j] = std::clamp(out[j], lo[j], hi[j]);
}

Quadric AttributeStore::reduced(const HalfEdgeBuffer& buffer, uint32_t v) const {
    double local[AttributeQuadric::size(kMaxAttributeComponents)], r[3];
    local_quadric(v, local);
    reference(buffer, v, r);
    const double t[3] = {-r[0], -r[1], -r[2]};
    return translated(AttributeQuadric::reduced(local, m_, omega()), t);
}

Quadric AttributeStore::merged_reduced(const HalfEdgeBuffer& buffer, uint32_t p, uint32_t q) const {
    // Summed in q's frame (p's translated by the short way t between the two reference points),
    // reduced there, and only the reduced quadric taken to the origin's frame; in one pass over
    // the two records (AttributeQuadric::add() and AttributeQuadric::reduced() written out).
    const float* a = record(q);
    const float* b = record(p);
    double rp[3], rq[3];
    reference(buffer, p, rp);
    reference(buffer, q, rq);
    const double t[3] = {rq[0] - rp[0], rq[1] - rp[1], rq[2] - rp[2]};
    Quadric sum = AttributeQuadric::part(a);
    sum += translated(AttributeQuadric::part(b), t);
    const double area = double(a[10]) + double(b[10]);
    if (area > 0) {
        const double* omega = this->omega();
        for (int j = 0; j < m_; ++j) {
            if (omega[j] == 0) continue;
            const float* ga = a + 11 + 4 * j;
            const float* gb = b + 11 + 4 * j;
            const double g[4] = {double(ga[0]) + double(gb[0]), double(ga[1]) + double(gb[1]),
                                 double(ga[2]) + double(gb[2]),
                                 double(ga[3]) + (double(gb[3]) + (double(gb[0]) * t[0] + double(gb[1]) * t[1] +
                                                                   double(gb[2]) * t[2]))};
            AttributeQuadric::subtract_square(sum, omega[j] / area, g);
        }
    }
    const double to_origin[3] = {-rq[0], -rq[1], -rq[2]};
    return translated(sum, to_origin);
}

double AttributeStore::error(const HalfEdgeBuffer& buffer, uint32_t v, const double x[3], const float* values) const {
    double local[AttributeQuadric::size(kMaxAttributeComponents)], r[3];
    local_quadric(v, local);
    reference(buffer, v, r);
    const double y[3] = {x[0] - r[0], x[1] - r[1], x[2] - r[2]};
    return AttributeQuadric::error(local, m_, omega(), y, values);
}

double AttributeStore::combined_error(const Quadric& g, double geometric_error, double attribute_error) {
    const double w = g.a00 + g.a11 + g.a22;
    return (w > 0 ? std::max(0.0, geometric_error) / w : 0) + attribute_error;
}

}  // namespace meshstream::decimate
