// The channels of the in-core mesh (decimate/attributes.hpp): beside each vertex record of the
// half-edge buffer, its attribute quadric and its value; beside each face record, its material and
// face scalars, and the values of its corners at seam vertices. Allocated once with the buffer,
// only when the stream has channels to carry: a positions-only stream has none of it and pays
// nothing.
//
// A vertex's value is the value of all its corners unless it is a seam vertex (kSeam: its corners
// disagree, or its faces have different materials), whose corners keep their own values. A
// vertex that absorbed collapses gets, when written, the value that minimizes its attribute
// quadric at its final position, within the range of the input values merged into it.
//
// Memory: per vertex slot (3·N + 3 of them for a buffer of N triangles) one record of 14 + 5·m
// floats rounded up to whole cache lines (128 bytes for an RGB colour, m = 3): the attribute
// quadric in float (11 + 4·m), relative to the vertex's input position (3: near the vertex a
// value's interpolation is about the value itself, which float holds to 1e-7 of it; relative to
// the buffer's origin it would be the gradient extrapolated across the mesh), and its value (m);
// beside it the range of the input values merged into it (2·m floats) and, when the stream has
// materials, 4 bytes of material. Per face slot 12·m bytes of corner values (written only at seam
// vertices), 4 of material and 8 per face scalar when the stream has them. As with the buffer's
// own pools, only the touched part becomes resident (about N/2 vertices; corner values only
// round seams).
#pragma once

#include "decimate/attribute_quadric.hpp"
#include "decimate/attributes.hpp"
#include "decimate/halfedge_buffer.hpp"

#include <bit>
#include <cstdint>

namespace meshstream::decimate {

class AttributeStore {
public:
    // Throws io::OptionError (Setting::kDrop) when the layout has more than
    // kMaxAttributeComponents.
    AttributeStore(const AttributeLayout& layout, size_t triangle_capacity);
    static size_t reserved_bytes(const AttributeLayout& layout, size_t triangle_capacity);

    const AttributeLayout& layout() const { return layout_; }
    int size() const { return m_; }
    const double* omega() const { return layout_.omega().data(); }
    // True when collapses are rated with attribute error (some channel weighs).
    bool weighted() const { return layout_.weighted(); }

    // READ: face f of `buffer` was just added with corner values `corners` (3·m floats, corner
    // k at k·m), `material` and `face_scalars` (face_scalar_count() doubles). Sets up new
    // vertices, marks seam vertices (kSeam) and adds the face's attribute quadric to its three.
    void add_face(HalfEdgeBuffer& buffer, uint32_t f, const float* corners, uint32_t material,
                  const double* face_scalars);
    // The values of a vertex that has not been seen yet (a triangle passed through).
    void ensure_vertex(HalfEdgeBuffer& buffer, uint32_t v, const float* value, uint32_t material);

    // The attribute error minimized over the values (AttributeQuadric::reduced) of v's quadric,
    // and of p's and q's summed, as quadrics in the position relative to the buffer's origin.
    Quadric reduced(const HalfEdgeBuffer& buffer, uint32_t v) const;
    Quadric merged_reduced(const HalfEdgeBuffer& buffer, uint32_t p, uint32_t q) const;
    // The attribute error of v's quadric at x (relative to the buffer's origin) with the values
    // fixed at `values`.
    double error(const HalfEdgeBuffer& buffer, uint32_t v, const double x[3], const float* values) const;
    double quadric_area(uint32_t v) const { return record(v)[10]; }
    // A cache hint for v's record (no effect on results).
    void prefetch(uint32_t v) const {
        const char* r = reinterpret_cast<const char*>(record(v));
        for (size_t b = 0; b < 4 * stride_; b += 64) __builtin_prefetch(r + b);
    }
    // A cache hint for the records merge() reads besides p's and q's quadrics: their value
    // ranges (no effect on results).
    void prefetch_merge(uint32_t p, uint32_t q) const {
        __builtin_prefetch(&ranges_[2 * size_t(p) * m_]);
        __builtin_prefetch(&ranges_[2 * size_t(q) * m_]);
    }
    float* vertex_value(uint32_t v) { return record(v) + value_offset_; }
    const float* vertex_value(uint32_t v) const { return record(v) + value_offset_; }
    // The smallest and largest input values of the vertices merged into v.
    float* range_lo(uint32_t v) { return &ranges_[2 * size_t(v) * m_]; }
    float* range_hi(uint32_t v) { return &ranges_[(2 * size_t(v) + 1) * m_]; }
    // Corner c (half-edge index 4·f + k) of an in-core face; valid where its vertex is a seam
    // vertex.
    float* corner_value(uint32_t c) { return &corners_[(3 * size_t(face_of(c)) + corner_of(c)) * m_]; }
    const float* corner_value(uint32_t c) const { return &corners_[(3 * size_t(face_of(c)) + corner_of(c)) * m_]; }
    // The value corner c shows: its own at a seam vertex, else its vertex's.
    const float* shown(const HalfEdgeBuffer& buffer, uint32_t c) const {
        const uint32_t v = buffer.corner_vertex(c);
        return (buffer.vertex(v).flags & kSeam) ? corner_value(c) : vertex_value(v);
    }
    uint32_t material(uint32_t f) const { return materials_ ? materials_[f] : 0; }
    const double* face_scalars(uint32_t f) const { return &face_scalars_[f * face_scalar_count_]; }

    // A collapse p→q of half-edge h is about to happen: p's corners take the value q shows on
    // their side of the seam (when q is a seam vertex), and q's quadric and range gain p's.
    void merge(HalfEdgeBuffer& buffer, uint32_t h);
    // True when seam vertex p may slide along its seam into q (h = p→q): p's one closed fan has
    // exactly two wedges (runs of corners that agree), h is one of the two edges between them,
    // and q is a seam vertex whose corners differ across h too (the seam goes on through q).
    // p's corners then take q's value on their side, and the seam loses p.
    bool slides(const HalfEdgeBuffer& buffer, uint32_t h) const;
    // The error of such a slide besides the geometric error at q: how far p lies off the seam's
    // line from its other seam neighbour r to q, in position (a distance², weighted by |r−q| like
    // the boundary planes) and, per side, in value (p's value against the interpolation of r's and
    // q's there, weighted by the area of p's faces on that side). `geometric` is added to the
    // first, `attribute` to the second.
    void slide_error(const HalfEdgeBuffer& buffer, uint32_t h, double& geometric, double& attribute) const;
    // True when a collapse into q along h keeps the seams: q is no seam vertex, or its corners
    // on the two faces of the edge agree (else the seam runs along the edge).
    bool seam_allows(const HalfEdgeBuffer& buffer, uint32_t h) const;
    // Vertex v is being written at its final position: a vertex that absorbed collapses takes
    // the values minimizing its attribute quadric there, each kept within the range of the input
    // values of the vertices merged into it.
    void settle(const HalfEdgeBuffer& buffer, uint32_t v);

    // The quadric (in the position) a collapse into a vertex of merged geometric quadric `g`
    // and reduced attribute quadric `r` is rated and placed by: g / W + r, W = trace of g (the
    // sum of its planes' weights), so the geometric part is a mean squared distance, as
    // meshoptimizer 1.2 rates collapses with attributes (attributes.hpp).
    static Quadric combined(const Quadric& g, const Quadric& r) {
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
    // The same rating from a geometric error of `g` and an attribute error.
    static double combined_error(const Quadric& g, double geometric_error, double attribute_error);

    // Vertices marked kSeam so far.
    uint64_t seam_vertices() const { return seam_vertices_; }
    // Non-finite input values replaced by 0 so far.
    uint64_t non_finite_values() const { return non_finite_; }
    // Replaces non-finite values of a corner vector by 0, counting them.
    void sanitize(float* values, size_t n);

private:
    // The m values at a and b are the same bit for bit (as memcmp tells, without a library
    // call for a few bytes).
    bool same_values(const float* a, const float* b) const {
        for (int j = 0; j < m_; ++j)
            if (std::bit_cast<uint32_t>(a[j]) != std::bit_cast<uint32_t>(b[j])) return false;
        return true;
    }
    // Corners c and d (of one vertex) show the same value on faces of the same material.
    bool same_wedge(uint32_t c, uint32_t d) const {
        return material(face_of(c)) == material(face_of(d)) &&
               same_values(corner_value(c), corner_value(d));
    }
    void init_vertex(HalfEdgeBuffer& buffer, uint32_t v, const float* value, uint32_t material);
    void make_seam(HalfEdgeBuffer& buffer, uint32_t v);
    float* record(uint32_t v) { return &records_[v * stride_]; }
    const float* record(uint32_t v) const { return &records_[v * stride_]; }
    // The reference point of v's quadric, relative to the buffer's origin.
    void reference(const HalfEdgeBuffer& buffer, uint32_t v, double r[3]) const;
    // Adds `q` (relative to the buffer's origin) to v's quadric.
    void add_quadric(const HalfEdgeBuffer& buffer, uint32_t v, const double* q);
    // v's record's quadric as doubles, relative to v's reference point.
    void local_quadric(uint32_t v, double* out) const {
        const float* q = record(v);
        for (size_t i = 0, n = AttributeQuadric::size(m_); i < n; ++i) out[i] = q[i];
    }

    AttributeLayout layout_;
    int m_;
    size_t stride_, value_offset_, face_scalar_count_;
    RawArray<float> records_;
    RawArray<float> ranges_;
    RawArray<uint32_t> vertex_material_;  // only with materials
    RawArray<float> corners_;
    RawArray<uint32_t> materials_;
    RawArray<double> face_scalars_;
    uint64_t non_finite_ = 0, seam_vertices_ = 0;
};

}  // namespace meshstream::decimate
