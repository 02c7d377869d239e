// Per-vertex and per-face channels of the in-core mesh, and the seam rules.
#include "decimate/attribute_store.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace meshstream::decimate {
namespace {

// Re-expresses a quadric given in y = x − a in y' = x − a' with t = a' − a: Q(y' + t) has
// b + A t and c + 2 bᵀt + tᵀA t.
Quadric translated(Quadric a, const double t[3]) {
    const double at[3] = {a.a00 * t[0] + a.a01 * t[1] + a.a02 * t[2], a.a01 * t[0] + a.a11 * t[1] + a.a12 * t[2],
                          a.a02 * t[0] + a.a12 * t[1] + a.a22 * t[2]};
    a.c += 2 * (a.b0 * t[0] + a.b1 * t[1] + a.b2 * t[2]) + (at[0] * t[0] + at[1] * t[1] + at[2] * t[2]);
    a.b0 += at[0];
    a.b1 += at[1];
    a.b2 += at[2];
    return a;
}

// The same for a whole attribute quadric: its values G·(y' + t) + D have D + G·t.
void translate(double* q, int m, const double t[3]) {
    AttributeQuadric::set_part(q, translated(AttributeQuadric::part(q), t));
    for (int j = 0; j < m; ++j) {
        double* g = q + 11 + 4 * j;
        g[3] += g[0] * t[0] + g[1] * t[1] + g[2] * t[2];
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
        throw std::invalid_argument(std::to_string(m_) + " attribute values per corner, more than the " +
                                    std::to_string(kMaxAttributeComponents) + " the decimator carries");
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

void AttributeStore::add_quadric(const HalfEdgeBuffer& buffer, uint32_t v, const double* q, const double at[3]) {
    double r[3], local[AttributeQuadric::size(kMaxAttributeComponents)];
    reference(buffer, v, r);
    const size_t n = AttributeQuadric::size(m_);
    std::copy_n(q, n, local);
    const double t[3] = {r[0] - at[0], r[1] - at[1], r[2] - at[2]};  // from x − at to x − r
    translate(local, m_, t);
    float* stored = record(v);
    for (size_t i = 0; i < n; ++i) stored[i] = float(double(stored[i]) + local[i]);
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
                                            std::memcmp(vertex_value(v[k]), value, 4 * m) != 0)) {
            make_seam(buffer, v[k]);  // this face's corner is linked already: overwritten below
        }
        if (buffer.vertex(v[k]).flags & kSeam) std::copy_n(value, m, corner_value(half_edge(f, k)));
    }
    if (m == 0) return;
    double q[AttributeQuadric::size(kMaxAttributeComponents)];
    AttributeQuadric::from_triangle(q, p[0], p[1], p[2], corners, corners + m, corners + 2 * m, m_, omega());
    const double origin[3] = {0, 0, 0};
    for (uint32_t k = 0; k < 3; ++k) add_quadric(buffer, v[k], q, origin);
}

bool AttributeStore::seam_allows(const HalfEdgeBuffer& buffer, uint32_t h) const {
    const uint32_t q_corner = next_in_face(h);
    const uint32_t q = buffer.corner_vertex(q_corner);
    if ((buffer.vertex(q).flags & kSeam) == 0) return true;
    const uint32_t t = buffer.twin(h);
    if (!is_half_edge(t)) return true;  // one face on the edge: one side
    // t runs q→p: its corner is q's on the other face.
    return material(face_of(h)) == material(face_of(t)) &&
           std::memcmp(corner_value(q_corner), corner_value(t), 4 * size_t(m_)) == 0;
}

void AttributeStore::merge(HalfEdgeBuffer& buffer, uint32_t h) {
    const uint32_t p = buffer.corner_vertex(h), q_corner = next_in_face(h), q = buffer.corner_vertex(q_corner);
    if (buffer.vertex(q).flags & kSeam) {
        // p's corners join q on h's side of the seam: they show q's value there.
        const float* wedge = corner_value(q_corner);
        for (uint32_t c = buffer.vertex(p).first_corner; c != kNoIndex; c = buffer.next_corner(c))
            std::copy_n(wedge, m_, corner_value(c));
    }
    // p's quadric, relative to p's reference point, into q's.
    double from_p[AttributeQuadric::size(kMaxAttributeComponents)], rp[3];
    local_quadric(p, from_p);
    reference(buffer, p, rp);
    add_quadric(buffer, q, from_p, rp);
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
    // Summed in q's frame (p's translated by the short way between the two reference points),
    // reduced there, and only the reduced quadric taken to the origin's frame.
    double a[AttributeQuadric::size(kMaxAttributeComponents)], b[AttributeQuadric::size(kMaxAttributeComponents)];
    double rp[3], rq[3];
    local_quadric(q, a);
    local_quadric(p, b);
    reference(buffer, p, rp);
    reference(buffer, q, rq);
    const double to_q[3] = {rq[0] - rp[0], rq[1] - rp[1], rq[2] - rp[2]};
    translate(b, m_, to_q);
    AttributeQuadric::add(a, b, m_);
    const double t[3] = {-rq[0], -rq[1], -rq[2]};
    return translated(AttributeQuadric::reduced(a, m_, omega()), t);
}

double AttributeStore::error(const HalfEdgeBuffer& buffer, uint32_t v, const double x[3], const float* values) const {
    double local[AttributeQuadric::size(kMaxAttributeComponents)], r[3];
    local_quadric(v, local);
    reference(buffer, v, r);
    const double y[3] = {x[0] - r[0], x[1] - r[1], x[2] - r[2]};
    return AttributeQuadric::error(local, m_, omega(), y, values);
}

Quadric AttributeStore::combined(const Quadric& g, const Quadric& r) {
    const double w = g.a00 + g.a11 + g.a22;
    const double s = w > 0 ? 1 / w : 0;
    Quadric out = r;
    out.a00 += s * g.a00;
    out.a01 += s * g.a01;
    out.a02 += s * g.a02;
    out.a11 += s * g.a11;
    out.a12 += s * g.a12;
    out.a22 += s * g.a22;
    out.b0 += s * g.b0;
    out.b1 += s * g.b1;
    out.b2 += s * g.b2;
    out.c += s * g.c;
    return out;
}

double AttributeStore::combined_error(const Quadric& g, double geometric_error, double attribute_error) {
    const double w = g.a00 + g.a11 + g.a22;
    return (w > 0 ? std::max(0.0, geometric_error) / w : 0) + attribute_error;
}

}  // namespace meshstream::decimate
