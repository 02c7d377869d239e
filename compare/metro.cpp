// Metro-style error between two meshes (Cignoni, Rocchini & Scopigno 1998), streaming the
// larger one. See metro.hpp for the method and its memory bound. Spatial indices are BVHs
// built by median split on the longest centroid axis (leaf 4 triangles / 8 samples); distances
// use Ericson's closest point on a triangle (Real-Time Collision Detection, §5.1.5) in double,
// whose barycentric coordinates also interpolate the attributes at that point.
#include "compare/metro.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/random.hpp"
#include "sort/radix.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

namespace meshstream::compare {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// splitmix64: each triangle's random numbers depend only on the seed and the triangle's
// index, not on chunk sizes.
using Rng = io::SplitMix64;

Rng triangle_rng(uint64_t seed, uint64_t salt, uint64_t index) {
    Rng r{seed * 0xD1B54A32D192ED03ull ^ salt};
    r.state ^= Rng{index}.next();
    return r;
}

bool finite_triangle(const float* t) {
    for (int k = 0; k < 9; ++k)
        if (!std::isfinite(t[k])) return false;
    return true;
}

double triangle_area(const float* t) {
    double e1[3], e2[3];
    for (int a = 0; a < 3; ++a) {
        e1[a] = double(t[3 + a]) - t[a];
        e2[a] = double(t[6 + a]) - t[a];
    }
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
}

// A uniformly distributed point on triangle t (Osada et al. 2002: sqrt of r1), and its
// barycentric coordinates.
void point_in_triangle(const float* t, Rng& rng, double p[3], double bary[3]) {
    double s = std::sqrt(rng.uniform()), r2 = rng.uniform();
    double wa = 1 - s, wb = s * (1 - r2), wc = s * r2;
    for (int a = 0; a < 3; ++a) p[a] = wa * t[a] + wb * t[3 + a] + wc * t[6 + a];
    bary[0] = wa, bary[1] = wb, bary[2] = wc;
}

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Squared distance from p to segment a-b, and in `t` where its closest point lies (0 at a, 1 at b).
double segment_dist2(const double p[3], const double a[3], const double b[3], double& t) {
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    double len2 = dot3(ab, ab);
    t = len2 > 0 ? std::clamp(dot3(ap, ab) / len2, 0.0, 1.0) : 0.0;
    double d[3] = {ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]};
    return dot3(d, d);
}

// Sets bary to (u, v, w) when kBary (the callers that need no coordinates skip the stores).
template <bool kBary>
void set_bary(double* bary, double u, double v, double w) {
    if constexpr (kBary) bary[0] = u, bary[1] = v, bary[2] = w;
}

// The nearest of a degenerate triangle's three edges (the first of equals, ab, bc, ca), with
// the barycentric coordinates of its closest point when kBary.
template <bool kBary>
double edges_dist2(const double p[3], const double a[3], const double b[3], const double c[3], double* bary) {
    double t_ab, t_bc, t_ac;
    const double ab = segment_dist2(p, a, b, t_ab), bc = segment_dist2(p, b, c, t_bc),
                 ac = segment_dist2(p, a, c, t_ac);
    if (ab <= bc && ab <= ac) {
        set_bary<kBary>(bary, 1 - t_ab, t_ab, 0);
        return ab;
    }
    if (bc <= ac) {
        set_bary<kBary>(bary, 0, 1 - t_bc, t_bc);
        return bc;
    }
    set_bary<kBary>(bary, 1 - t_ac, 0, t_ac);
    return ac;
}

// Squared distance from p to triangle t (9 floats), Ericson §5.1.5 by Voronoi regions, and
// with kBary the barycentric coordinates of the closest point in bary[3] (else bary is not
// used and may be null). A degenerate triangle (zero area) falls back to its three edges,
// where the region divisions would be 0/0.
template <bool kBary = false>
double point_triangle_dist2(const double p[3], const float* t, double* bary = nullptr) {
    double a[3] = {t[0], t[1], t[2]}, b[3] = {t[3], t[4], t[5]}, c[3] = {t[6], t[7], t[8]};
    double ab[3], ac[3], ap[3], q[3];
    for (int k = 0; k < 3; ++k) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
    auto dist2_to = [&](const double* x) {
        double d[3] = {p[0] - x[0], p[1] - x[1], p[2] - x[2]};
        return dot3(d, d);
    };
    auto corner = [&](const double* x, int k) {
        set_bary<kBary>(bary, k == 0, k == 1, k == 2);
        return dist2_to(x);
    };
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) return corner(a, 0);
    double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) return corner(b, 1);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        if (d1 - d3 <= 0) return edges_dist2<kBary>(p, a, b, c, bary);
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + v * ab[k];
        set_bary<kBary>(bary, 1 - v, v, 0);
        return dist2_to(q);
    }
    double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) return corner(c, 2);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        if (d2 - d6 <= 0) return edges_dist2<kBary>(p, a, b, c, bary);
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + w * ac[k];
        set_bary<kBary>(bary, 1 - w, 0, w);
        return dist2_to(q);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double den = (d4 - d3) + (d5 - d6);
        if (den <= 0) return edges_dist2<kBary>(p, a, b, c, bary);
        double w = (d4 - d3) / den;
        for (int k = 0; k < 3; ++k) q[k] = b[k] + w * (c[k] - b[k]);
        set_bary<kBary>(bary, 0, 1 - w, w);
        return dist2_to(q);
    }
    double sum = va + vb + vc;
    if (!(sum > 0)) return edges_dist2<kBary>(p, a, b, c, bary);
    double v = vb / sum, w = vc / sum;
    for (int k = 0; k < 3; ++k) q[k] = a[k] + ab[k] * v + ac[k] * w;
    set_bary<kBary>(bary, 1 - v - w, v, w);
    return dist2_to(q);
}

// ---- Attributes ----------------------------------------------------------------------------

// The attribute values compare measures, packed per corner (and per sample) as floats:
// colour RGB first when measured, then the normal's xyz.
struct AttributeLayout {
    bool color = false, normal = false;
    int floats() const { return 3 * (int(color) + int(normal)); }
    int normal_offset() const { return color ? 3 : 0; }
};

// Packs the three corners of chunk triangle i into out[3 × layout.floats()].
void pack_corners(const AttributeLayout& layout, const io::TriangleChunk& chunk, size_t i, float* out) {
    const int n = layout.floats();
    const float* rgba = layout.color ? chunk.color_at(i) : nullptr;
    const float* normal = layout.normal ? chunk.normal_at(i) : nullptr;
    for (int k = 0; k < 3; ++k) {
        float* corner = out + k * n;
        if (rgba) std::memcpy(corner, rgba + 4 * k, 3 * sizeof(float));
        if (normal) std::memcpy(corner + layout.normal_offset(), normal + 3 * k, 3 * sizeof(float));
    }
}

// out[j] = the corners' values (3 × n floats) interpolated at barycentric coordinates `bary`.
void interpolate(const float* corners, int n, const double bary[3], float* out) {
    for (int j = 0; j < n; ++j)
        out[j] = float(bary[0] * corners[j] + bary[1] * corners[n + j] + bary[2] * corners[2 * n + j]);
}

struct ErrorAccumulator {
    uint64_t n = 0, skipped = 0;
    double sum2 = 0, max = 0;
    void add(double error) {
        if (!std::isfinite(error)) {
            ++skipped;
            return;
        }
        ++n;
        sum2 += error * error;
        max = std::max(max, error);
    }
    AttributeStats stats() const {
        AttributeStats s;
        s.samples = n;
        s.skipped = skipped;
        s.max = max;
        s.rms = n ? std::sqrt(sum2 / double(n)) : 0;
        return s;
    }
};

// One direction's colour and normal errors.
struct AttributeAccumulator {
    AttributeLayout layout;
    ErrorAccumulator color, normal;

    // A sample's value on its own surface against the value at its nearest point of the other.
    void add(const float* own, const float* other) {
        if (layout.color) {
            double d2 = 0;
            for (int j = 0; j < 3; ++j) {
                const double d = double(own[j]) - other[j];
                d2 += d * d;
            }
            color.add(std::sqrt(d2));
        }
        if (layout.normal) {
            const float *a = own + layout.normal_offset(), *b = other + layout.normal_offset();
            const double x[3] = {a[0], a[1], a[2]}, y[3] = {b[0], b[1], b[2]};
            if (!(dot3(x, x) > 0) || !(dot3(y, y) > 0)) {
                ++normal.skipped;  // no direction to compare (or NaN)
            } else {
                // atan2 of |x × y| and x · y: the angle of the normalised vectors, exact near 0°
                // and 180°, where acos of the dot product loses half its digits.
                const double c[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
                normal.add(std::atan2(std::sqrt(dot3(c, c)), dot3(x, y)) * (180.0 / 3.14159265358979323846));
            }
        }
    }
};

// ---- BVH over boxes ------------------------------------------------------------------------

struct BvhNode {
    float lo[3], hi[3];
    uint32_t first;  // leaf: first primitive; inner: index of the left child (right = first + 1)
    uint32_t count;  // primitives in a leaf, 0 for an inner node
};

// Builds a BVH over n primitives whose boxes `box(i, lo, hi)` gives. Returns the nodes and
// writes the primitive order into `order` (the caller permutes its data by it). The primitives
// go in the Morton order of their centroids (10 bits an axis over the centroids' box, radix
// sorted, ties in input order), then split top down where the highest bit of the code changes
// (an octree's split along one axis; in the middle of a run of equal codes), down to
// `leaf_size`; the boxes are then set bottom up. Linear but for the sort's three passes, so a
// build costs about what a few queries a primitive cost: the tiles' errors build an index for
// about one query a triangle. Depth: at most 30 splits by bits, then halvings.
template <class BoxFn>
std::vector<BvhNode> build_bvh(uint32_t n, BoxFn box, uint32_t leaf_size, std::vector<uint32_t>& order) {
    std::vector<BvhNode> nodes;
    order.resize(n);
    if (n == 0) return nodes;
    // The centroids' box, then their codes (each box computed twice: no array of centroids).
    auto centroid = [&](uint32_t i, float c[3]) {
        float lo[3], hi[3];
        box(i, lo, hi);
        for (int a = 0; a < 3; ++a) c[a] = 0.5f * (lo[a] + hi[a]);
    };
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; ++i) {
        float c[3];
        centroid(i, c);
        for (int a = 0; a < 3; ++a) clo[a] = std::min(clo[a], c[a]), chi[a] = std::max(chi[a], c[a]);
    }
    std::vector<uint64_t> items(n);  // (code << 32 | primitive)
    {
        float scale[3];
        for (int a = 0; a < 3; ++a) scale[a] = chi[a] > clo[a] ? 1023.0f / (chi[a] - clo[a]) : 0.0f;
        for (uint32_t i = 0; i < n; ++i) {
            float c[3];
            centroid(i, c);
            uint32_t q[3];
            for (int a = 0; a < 3; ++a) {
                const float t = (c[a] - clo[a]) * scale[a];
                q[a] = t > 0 ? uint32_t(std::min(t, 1023.0f)) : 0;  // NaN: 0
            }
            items[i] = uint64_t{sort::morton30(q[0], q[1], q[2])} << 32 | i;
        }
        std::vector<uint64_t> scratch(n);
        if (sort::radix_sort_by_key(items, scratch).data() == scratch.data()) items.swap(scratch);
    }
    for (uint32_t k = 0; k < n; ++k) order[k] = uint32_t(items[k]);
    nodes.reserve(2 * (size_t{n} / leaf_size + 1));
    nodes.push_back({});
    struct Job {
        uint32_t node, begin, end;
    };
    std::vector<Job> stack{{0, 0, n}};
    while (!stack.empty()) {
        Job job = stack.back();
        stack.pop_back();
        if (job.end - job.begin <= leaf_size) {
            nodes[job.node].first = job.begin;
            nodes[job.node].count = job.end - job.begin;
            continue;
        }
        const uint32_t first = uint32_t(items[job.begin] >> 32), last = uint32_t(items[job.end - 1] >> 32);
        uint32_t mid = job.begin + (job.end - job.begin) / 2;
        if (first != last) {
            // The first code with the highest differing bit set (all share the bits above).
            const uint32_t bit = uint32_t{1} << (31 - std::countl_zero(first ^ last));
            mid = uint32_t(std::partition_point(items.begin() + job.begin, items.begin() + job.end,
                                                [&](uint64_t v) { return !(uint32_t(v >> 32) & bit); }) -
                           items.begin());
        }
        uint32_t left = static_cast<uint32_t>(nodes.size());
        nodes[job.node].first = left;
        nodes[job.node].count = 0;
        nodes.push_back({});
        nodes.push_back({});
        stack.push_back({left, job.begin, mid});
        stack.push_back({left + 1, mid, job.end});
    }
    // Children come after their parent: in reverse, every node's children are done before it.
    for (size_t j = nodes.size(); j-- > 0;) {
        BvhNode& node = nodes[j];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        auto add = [&](const float blo[3], const float bhi[3]) {
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], blo[a]);
                hi[a] = std::max(hi[a], bhi[a]);
            }
        };
        if (node.count > 0) {
            for (uint32_t k = node.first; k < node.first + node.count; ++k) {
                float blo[3], bhi[3];
                box(order[k], blo, bhi);
                add(blo, bhi);
            }
        } else {
            add(nodes[node.first].lo, nodes[node.first].hi);
            add(nodes[node.first + 1].lo, nodes[node.first + 1].hi);
        }
        std::memcpy(node.lo, lo, sizeof lo);
        std::memcpy(node.hi, hi, sizeof hi);
    }
    return nodes;
}

template <class T>
void permute(std::vector<T>& data, const std::vector<uint32_t>& order, size_t stride) {
    std::vector<T> out(data.size());
    for (size_t i = 0; i < order.size(); ++i)
        std::memcpy(&out[stride * i], &data[stride * order[i]], stride * sizeof(T));
    data.swap(out);
}

double box_dist2(const BvhNode& n, const double p[3]) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
        double d = std::max({double(n.lo[a]) - p[a], 0.0, p[a] - double(n.hi[a])});
        d2 += d * d;
    }
    return d2;
}

// Nearest primitive to p: returns the smallest leaf_dist2(i) below `best2`, or best2; and in
// *winner (when not null) that primitive, left alone when none is below best2. With kAny, the
// search stops at the first primitive below best2 (nearer boxes first), returning its distance:
// whether some primitive is, not which is nearest.
template <bool kAny = false, class LeafFn>
double bvh_nearest(const std::vector<BvhNode>& nodes, const double p[3], double best2, LeafFn leaf_dist2,
                   uint32_t* winner = nullptr) {
    if (nodes.empty()) return best2;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& n = nodes[stack[--top]];
        // (With kAny, best2 has not moved since the node was pushed below it.)
        if (!kAny && box_dist2(n, p) >= best2) continue;
        if (n.count) {
            for (uint32_t i = n.first; i < n.first + n.count; ++i) {
                const double d2 = leaf_dist2(i);
                if constexpr (kAny) {
                    if (d2 < best2) return d2;
                }
                if (winner && d2 < best2) *winner = i;
                best2 = std::min(best2, d2);  // a min, not a branch on d2: the hot loop of compare
            }
            continue;
        }
        double dl = box_dist2(nodes[n.first], p), dr = box_dist2(nodes[n.first + 1], p);
        // Push the farther child first so the nearer one is searched first.
        if (dl <= dr) {
            if (dr < best2) stack[top++] = n.first + 1;
            if (dl < best2) stack[top++] = n.first;
        } else {
            if (dl < best2) stack[top++] = n.first;
            if (dr < best2) stack[top++] = n.first + 1;
        }
    }
    return best2;
}

// Triangles held in memory, with their BVH and their corners' attribute values.
struct TriangleIndex {
    std::vector<float> xyz;            // 9 floats per triangle, in BVH order
    int values = 0;                    // attribute floats per corner (AttributeLayout::floats())
    std::vector<float> corner_values;  // 3 × values floats per triangle, in BVH order
    std::vector<BvhNode> nodes;

    void build() {
        std::vector<uint32_t> order;
        nodes = build_bvh(
            static_cast<uint32_t>(xyz.size() / 9),
            [&](uint32_t i, float lo[3], float hi[3]) {
                const float* t = &xyz[9 * size_t{i}];
                for (int a = 0; a < 3; ++a) {
                    lo[a] = std::min({t[a], t[3 + a], t[6 + a]});
                    hi[a] = std::max({t[a], t[3 + a], t[6 + a]});
                }
            },
            4, order);
        permute(xyz, order, 9);
        if (values) permute(corner_values, order, 3 * size_t(values));
    }
    // The squared distance from p to the nearest triangle at or below best2 (else best2), and
    // when `value` is not null and one is, the attribute values at its closest point in
    // value[values].
    double nearest_dist2(const double p[3], double best2 = kInf, float* value = nullptr) const {
        uint32_t winner = 0;
        const double d2 = bvh_nearest(
            nodes, p, best2, [&](uint32_t i) { return point_triangle_dist2(p, &xyz[9 * size_t{i}]); },
            value ? &winner : nullptr);
        if (value && d2 < best2) {  // the winner's coordinates, once
            double bary[3];
            point_triangle_dist2<true>(p, &xyz[9 * size_t{winner}], bary);
            interpolate(&corner_values[3 * size_t(values) * winner], values, bary, value);
        }
        return d2;
    }
    // Whether a triangle is nearer p than sqrt(r2).
    bool any_within(const double p[3], double r2) const {
        return bvh_nearest<true>(nodes, p, r2, [&](uint32_t i) { return point_triangle_dist2(p, &xyz[9 * size_t{i}]); }) < r2;
    }
};

// Held samples farther than this many typical streamed triangle sizes from the streamed surface
// (by their upper bound) meet the streamed triangles kChunkTriangles at a time.
constexpr double kFarFactor = 8;
constexpr size_t kChunkTriangles = 1024;

// Samples of the in-memory mesh, each with the running minimum of its squared distance to the
// streamed mesh. Leaf boxes are the samples inflated by their initial upper bound, so a
// triangle that can lower a sample's distance always overlaps the sample's box.
struct SampleIndex {
    // Samples are kept as floats relative to `origin` (a corner of the held mesh): absolute
    // floats far from the origin round by up to half a float step, 0.125 m at 4 000 000 as in
    // UTM coordinates, which showed as error in a mesh compared with itself.
    double origin[3] = {0, 0, 0};
    std::vector<float> xyz;  // 3 floats per sample relative to origin, in BVH order
    // Attribute floats per sample (AttributeLayout::floats()), and the samples' values: their
    // own, and at their nearest point of the streamed mesh so far (the point best2 measures).
    // They stay in the order the samples were added (a permuted copy would double the largest
    // part of compare's memory): sample i's are at record slot[i].
    int values = 0;
    std::vector<float> own, other;  // `values` floats per sample each
    std::vector<uint32_t> slot;     // with values, after build()
    std::vector<double> best2;      // running minimum squared distance
    std::vector<BvhNode> nodes;

    // Appends a sample at p with its own attribute values (`values` floats; may be null when
    // values is 0).
    void add(const double p[3], const float* own_values) {
        xyz.insert(xyz.end(), {float(p[0] - origin[0]), float(p[1] - origin[1]), float(p[2] - origin[2])});
        if (values) own.insert(own.end(), own_values, own_values + values);
    }
    // Appends sample i of `from` (before its build()), which has the same origin and values, as
    // it stands.
    void add_from(const SampleIndex& from, size_t i) {
        xyz.insert(xyz.end(), &from.xyz[3 * i], &from.xyz[3 * i] + 3);
        if (!values) return;
        own.insert(own.end(), &from.own[values * i], &from.own[values * i] + values);
        other.insert(other.end(), &from.other[values * i], &from.other[values * i] + values);
    }
    void position(size_t i, double p[3]) const {
        for (int a = 0; a < 3; ++a) p[a] = double(xyz[3 * i + a]) + origin[a];
    }

    void build(std::vector<double> bound2) {
        std::vector<uint32_t> order;
        std::vector<float> radius(bound2.size());
        for (size_t i = 0; i < bound2.size(); ++i) {
            const float* s = &xyz[3 * i];
            float scale = std::max({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])});
            // Inflate for the float rounding of the box corners.
            radius[i] = float(std::sqrt(bound2[i]) * (1 + 1e-5)) + scale * 1e-6f + 1e-30f;
        }
        nodes = build_bvh(
            static_cast<uint32_t>(bound2.size()),
            [&](uint32_t i, float lo[3], float hi[3]) {
                for (int a = 0; a < 3; ++a) {
                    lo[a] = xyz[3 * size_t{i} + a] - radius[i];
                    hi[a] = xyz[3 * size_t{i} + a] + radius[i];
                }
            },
            8, order);
        permute(xyz, order, 3);
        best2.resize(bound2.size());
        for (size_t i = 0; i < order.size(); ++i) best2[i] = bound2[order[i]];
        if (values) slot = std::move(order);
    }

    // Lowers best2 of every sample that triangle t (absolute bounding box abs_lo..abs_hi) is
    // closer to, and sets its `other` values to those interpolated at its closest point of t
    // from t's corners (3 × values floats; may be null when values is 0).
    void update(const float* t, const float* corners, const float abs_lo[3], const float abs_hi[3]) {
        if (!values) {
            lower_within(abs_lo, abs_hi, [&](size_t, const double p[3], double so_far) {
                return std::min(so_far, point_triangle_dist2(p, t));
            });
            return;
        }
        lower_within(abs_lo, abs_hi, [&](size_t i, const double p[3], double so_far) {
            double bary[3];
            const double d2 = point_triangle_dist2<true>(p, t, bary);
            if (!(d2 < so_far)) return so_far;
            interpolate(corners, values, bary, &other[values * size_t{slot[i]}]);
            return d2;
        });
    }
    // The same for every triangle of `chunk` (abs_lo..abs_hi bounds them all), through its BVH:
    // for samples far from the streamed surface, which a triangle at a time would meet once for
    // every triangle within reach.
    void update(const TriangleIndex& chunk, const float abs_lo[3], const float abs_hi[3]) {
        lower_within(abs_lo, abs_hi, [&](size_t i, const double p[3], double so_far) {
            return chunk.nearest_dist2(p, so_far, values ? &other[values * size_t{slot[i]}] : nullptr);
        });
    }

private:
    // Calls best2[i] = lower(i, p_i, best2[i]) for every sample i whose box reaches abs_lo..abs_hi
    // and that box is nearer than best2[i].
    template <class Lower>
    void lower_within(const float abs_lo[3], const float abs_hi[3], Lower lower) {
        if (nodes.empty()) return;
        float lo[3], hi[3];  // the box relative to origin, rounded outwards
        for (int a = 0; a < 3; ++a) {
            const double l = double(abs_lo[a]) - origin[a], h = double(abs_hi[a]) - origin[a];
            lo[a] = float(l);
            hi[a] = float(h);
            if (double(lo[a]) > l) lo[a] = std::nextafter(lo[a], -INFINITY);
            if (double(hi[a]) < h) hi[a] = std::nextafter(hi[a], INFINITY);
        }
        uint32_t stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const BvhNode& n = nodes[stack[--top]];
            if (n.lo[0] > hi[0] || n.hi[0] < lo[0] || n.lo[1] > hi[1] || n.hi[1] < lo[1] || n.lo[2] > hi[2] ||
                n.hi[2] < lo[2])
                continue;
            if (!n.count) {
                stack[top++] = n.first;
                stack[top++] = n.first + 1;
                continue;
            }
            for (uint32_t i = n.first; i < n.first + n.count; ++i) {
                double p[3];
                position(i, p);
                double box2 = 0;
                for (int a = 0; a < 3; ++a) {
                    double d = std::max({double(abs_lo[a]) - p[a], 0.0, p[a] - double(abs_hi[a])});
                    box2 += d * d;
                }
                if (box2 >= best2[i]) continue;
                best2[i] = lower(i, p, best2[i]);
            }
        }
    }
};

struct StatsAccumulator {
    uint64_t n = 0;
    double sum = 0, sum2 = 0, max = 0;
    void add(double dist2) {
        double d = std::sqrt(dist2);
        ++n;
        sum += d;
        sum2 += dist2;
        max = std::max(max, d);
    }
    DistanceStats stats() const {
        DistanceStats s;
        s.samples = n;
        s.max = max;
        s.mean = n ? sum / double(n) : 0;
        s.rms = n ? std::sqrt(sum2 / double(n)) : 0;
        return s;
    }
};

void grow_bounds(io::Bounds& b, const float* t, bool& first) {
    if (first) {  // from the first corner only: each corner of the first triangle used to reset it
        for (int a = 0; a < 3; ++a) b.min[a] = b.max[a] = t[a];
        first = false;
    }
    for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a) {
            const float x = t[3 * v + a];
            b.min[a] = std::min(b.min[a], x);
            b.max[a] = std::max(b.max[a], x);
        }
}

// Reads the whole of `reader` through `fn(triangle_index, tri, corners)` for finite
// triangles, `corners` being the triangle's corners' values in `layout` (3 × layout.floats();
// null when the layout is empty); fills the summary's counts, area and bounds (edges when
// `edges` is given).
template <class Fn>
void stream_mesh(std::unique_ptr<io::Reader> reader, const AttributeLayout& layout, MeshSummary& summary,
                 EdgeCounter* edges, const CompareOptions& options, std::string_view phase, Fn fn) {
    std::optional<uint64_t> total = reader->triangle_count();
    io::Channels wanted;
    wanted.normal = layout.normal;
    if (layout.color) wanted.color = reader->header().channels.color.value_or(io::ColorFormat{});
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wanted);
    float corners[3 * 6];
    const float* values = layout.floats() ? corners : nullptr;
    uint64_t index = 0, non_finite = 0;
    double area = 0;
    bool first = true;
    io::Bounds bounds;
    while (reader->next(chunk)) {
        auto xyz = chunk.xyz();
        for (size_t t = 0; t < chunk.size(); ++t, ++index) {
            const float* tri = &xyz[9 * t];
            if (!finite_triangle(tri)) {
                ++non_finite;
                continue;
            }
            area += triangle_area(tri);
            grow_bounds(bounds, tri, first);
            if (edges) edges->add_triangle(tri);
            if (values) pack_corners(layout, chunk, t, corners);
            fn(index, tri, values);
        }
        if (options.progress) options.progress(phase, index, total);
    }
    summary.channels = reader->header().channels;
    summary.triangles = index;
    summary.non_finite_triangles = non_finite;
    summary.area = area;
    summary.bounds = bounds;
}

constexpr uint64_t kSaltMemorySamples = 0x6d656d6f7279ull;  // "memory"
constexpr uint64_t kSaltStreamSamples = 0x73747265616dull;  // "stream"
constexpr uint64_t kSaltReservoir = 0x7265736572766full;    // "reservo"

// Number of samples for a triangle of `area` at `density` (samples per unit area), with
// stochastic rounding so the total matches the request in expectation.
uint64_t samples_for(double area, double density, Rng& rng) {
    double expected = area * density;
    double whole = std::floor(expected);
    return static_cast<uint64_t>(whole) + (rng.uniform() < expected - whole ? 1 : 0);
}

class InputReader final : public io::Reader {
public:
    explicit InputReader(io::Input in) : in_(std::move(in)) { header_ = in_.reader->header(); }
    bool next(io::TriangleChunk& chunk) override { return in_.reader->next(chunk); }

private:
    io::Input in_;
};

// Triangles, and optionally their corners' normals (9 floats each) and colours (12), in memory.
struct MemoryMesh {
    std::vector<float> xyz, normals, colors;
};

class MemoryReader final : public io::Reader {
public:
    explicit MemoryReader(std::shared_ptr<const MemoryMesh> mesh) : mesh_(std::move(mesh)) {
        header_.triangle_count = mesh_->xyz.size() / 9;
        header_.channels.normal = !mesh_->normals.empty();
        if (!mesh_->colors.empty()) header_.channels.color = io::ColorFormat{io::ScalarType::kFloat32, true};
    }
    bool next(io::TriangleChunk& chunk) override {
        chunk.clear();
        size_t n = std::min(chunk.capacity(), mesh_->xyz.size() / 9 - pos_);
        std::memcpy(chunk.xyz_storage(), mesh_->xyz.data() + 9 * pos_, n * 9 * sizeof(float));
        // The chunk's other channels stay as they are, as a reader leaves channels it lacks.
        for (size_t i = 0; i < n; ++i) {
            if (float* normal = chunk.normal_at(i); normal && !mesh_->normals.empty())
                std::memcpy(normal, &mesh_->normals[9 * (pos_ + i)], 9 * sizeof(float));
            if (float* rgba = chunk.color_at(i); rgba && !mesh_->colors.empty())
                std::memcpy(rgba, &mesh_->colors[12 * (pos_ + i)], 12 * sizeof(float));
        }
        chunk.resize(n);
        pos_ += n;
        return n > 0;
    }

private:
    std::shared_ptr<const MemoryMesh> mesh_;
    size_t pos_ = 0;
};

}  // namespace

// ---- Sources -----------------------------------------------------------------------------

MeshSource file_source(const std::string& path, std::string_view from, const io::ReadOptions& options) {
    MeshSource s;
    s.name = path;
    s.once = io::is_stream(path);
    s.open = [path, from = std::string(from), options]() -> std::unique_ptr<io::Reader> {
        return std::make_unique<InputReader>(io::open_input(path, from, options));
    };
    return s;
}

MeshSource memory_source(std::string name, std::vector<float> xyz, std::vector<float> normals,
                         std::vector<float> colors) {
    assert(xyz.size() % 9 == 0);
    assert(normals.empty() || normals.size() == xyz.size());
    assert(colors.empty() || 3 * colors.size() == 4 * xyz.size());
    MeshSource s;
    s.name = std::move(name);
    auto data = std::make_shared<const MemoryMesh>(MemoryMesh{std::move(xyz), std::move(normals), std::move(colors)});
    s.open = [data]() -> std::unique_ptr<io::Reader> { return std::make_unique<MemoryReader>(data); };
    return s;
}

uint64_t default_sample_count(uint64_t triangle_count) {
    constexpr uint64_t kMin = 1'000'000, kMax = 10'000'000;
    return std::clamp(triangle_count > kMax ? kMax : 10 * triangle_count, kMin, kMax);
}

double MeshSummary::diagonal() const {
    if (triangles == non_finite_triangles) return 0;
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
        double d = double(bounds.max[a]) - bounds.min[a];
        d2 += d * d;
    }
    return std::sqrt(d2);
}

// ---- compare_meshes ----------------------------------------------------------------------

AttributeStats AttributeErrors::symmetric(const AttributeStats& x, const AttributeStats& y) {
    AttributeStats s;
    s.samples = x.samples + y.samples;
    s.skipped = x.skipped + y.skipped;
    s.max = std::max(x.max, y.max);
    s.rms = std::max(x.rms, y.rms);
    return s;
}

namespace {

// "colours and normals", "colours", "normals" or "neither colours nor normals".
std::string describe_attributes(const io::Channels& c) {
    if (c.color && c.normal) return "colours and normals";
    if (c.color) return "colours";
    if (c.normal) return "normals";
    return "neither colours nor normals";
}

}  // namespace

double one_sided_hausdorff(const std::vector<float>& from, std::vector<float> to, uint64_t samples, uint64_t seed) {
    TriangleIndex index;
    size_t kept = 0;  // the finite triangles moved down in place
    for (size_t t = 0; t + 9 <= to.size(); t += 9)
        if (finite_triangle(&to[t])) {
            if (kept != t) std::copy_n(&to[t], 9, &to[kept]);
            kept += 9;
        }
    to.resize(kept);
    index.xyz = std::move(to);
    if (index.xyz.empty()) return 0;
    index.build();
    double area = 0;
    for (size_t t = 0; t + 9 <= from.size(); t += 9)
        if (finite_triangle(&from[t])) area += triangle_area(&from[t]);
    if (!(area > 0)) return 0;
    const double density = double(samples) / area;
    // Only the largest distance counts: a sample is first looked for within the largest so far
    // (a search that small is quick), and measured in full only when nothing is that near.
    double max2 = 0;
    for (size_t t = 0; t + 9 <= from.size(); t += 9) {
        const float* tri = &from[t];
        if (!finite_triangle(tri)) continue;
        Rng rng = triangle_rng(seed, kSaltMemorySamples, t / 9);
        for (uint64_t k = samples_for(triangle_area(tri), density, rng); k > 0; --k) {
            double p[3], bary[3];
            point_in_triangle(tri, rng, p, bary);
            if (max2 > 0 && index.any_within(p, max2)) continue;
            max2 = std::max(max2, index.nearest_dist2(p));
        }
    }
    return std::sqrt(max2);
}

CompareResult compare_meshes(const MeshSource& a, const MeshSource& b, const CompareOptions& options) {
    // Which one to hold: the smaller by header count (or a PLY's face count) when both are
    // known, else B. A stream cannot be read twice (nor opened once just for its count), so it
    // is always the held one.
    if (a.once && b.once)
        throw io::Error(b.name, "compare cannot stream both meshes (stdin or pipes): one of them is read twice");
    bool hold_a = a.once;
    std::optional<io::Channels> channels_a, channels_b;  // from the headers, where opened for counts
    if (!a.once && !b.once) {
        auto count = [](const MeshSource& m, std::optional<io::Channels>& channels) {
            const std::unique_ptr<io::Reader> reader = m.open();
            const io::MeshHeader& h = reader->header();
            channels = h.channels;
            return h.triangle_count ? h.triangle_count : h.triangle_estimate;
        };
        const std::optional<uint64_t> count_a = count(a, channels_a), count_b = count(b, channels_b);
        hold_a = count_a && count_b && *count_a < *count_b;
    }
    const MeshSource& held = hold_a ? a : b;
    const MeshSource& streamed = hold_a ? b : a;

    MeshSummary held_summary, streamed_summary;
    held_summary.name = held.name;
    held_summary.in_memory = true;
    streamed_summary.name = streamed.name;

    // The channels both have decide what the held mesh keeps, so they are known before a
    // triangle is read: the held mesh's from its reader, the streamed one's from the count
    // above or, when the held mesh is a stream, from opening it once more (it is a file).
    std::unique_ptr<io::Reader> held_reader = held.open();
    held_summary.channels = held_reader->header().channels;
    AttributeLayout layout;
    if (options.attributes) {
        const std::optional<io::Channels>& known = hold_a ? channels_b : channels_a;
        streamed_summary.channels = known ? *known : streamed.open()->header().channels;
        layout.color = held_summary.channels.color && streamed_summary.channels.color;
        layout.normal = held_summary.channels.normal && streamed_summary.channels.normal;
        if (!layout.color && !layout.normal) {
            const MeshSummary& sa = hold_a ? held_summary : streamed_summary;
            const MeshSummary& sb = hold_a ? streamed_summary : held_summary;
            throw NoSharedAttributes("no colours or normals in both meshes to compare: A (" + a.name + ") has " +
                                     describe_attributes(sa.channels) + ", B (" + b.name + ") has " +
                                     describe_attributes(sb.channels));
        }
    }
    const int values = layout.floats();

    // The held mesh: triangles, their corners' values, edges, and later its samples.
    TriangleIndex triangles;
    triangles.values = values;
    {
        EdgeCounter edges(options.memory_budget_bytes, options.tmpdir);
        stream_mesh(std::move(held_reader), layout, held_summary, options.edges ? &edges : nullptr, options,
                    "reading " + held.name,
                    [&](uint64_t, const float* t, const float* corners) {
                        triangles.xyz.insert(triangles.xyz.end(), t, t + 9);
                        if (values)
                            triangles.corner_values.insert(triangles.corner_values.end(), corners,
                                                           corners + 3 * values);
                    });
        if (options.edges) held_summary.edges = edges.finish();
    }
    if (triangles.xyz.empty()) throw io::Error(held.name, "holds no (finite) triangles; nothing to compare");
    uint64_t held_samples = options.samples.value_or(default_sample_count(held_summary.triangles));

    // Pass 1 over the streamed mesh: counts, area, edges, and a reservoir of its vertices
    // (Vitter's algorithm R), whose distances to the held samples bound the true distances
    // from above before pass 2; with their values, which are then the held samples' values at
    // those (upper-bound) nearest points.
    std::vector<float> reservoir, reservoir_values;
    size_t reservoir_capacity = static_cast<size_t>(std::clamp<uint64_t>(held_samples, 1024, 10'000'000));
    {
        EdgeCounter edges(options.memory_budget_bytes, options.tmpdir);
        uint64_t seen = 0;
        stream_mesh(streamed.open(), layout, streamed_summary, options.edges ? &edges : nullptr, options,
                    "pass 1: " + streamed.name,
                    [&](uint64_t index, const float* t, const float* corners) {
                        Rng rng = triangle_rng(options.seed, kSaltReservoir, index);
                        const uint64_t k = rng.next() % 3;
                        const float* corner = t + 3 * k;
                        const float* value = values ? corners + k * values : nullptr;
                        if (seen < reservoir_capacity) {
                            reservoir.insert(reservoir.end(), corner, corner + 3);
                            if (values) reservoir_values.insert(reservoir_values.end(), value, value + values);
                        } else {
                            uint64_t slot = rng.next() % (seen + 1);
                            if (slot < reservoir_capacity) {
                                std::memcpy(&reservoir[3 * slot], corner, 3 * sizeof(float));
                                if (values)
                                    std::memcpy(&reservoir_values[values * slot], value, values * sizeof(float));
                            }
                        }
                        ++seen;
                    });
        if (options.edges) streamed_summary.edges = edges.finish();
    }
    if (reservoir.empty()) throw io::Error(streamed.name, "holds no (finite) triangles; nothing to compare");
    uint64_t streamed_samples = options.samples.value_or(default_sample_count(streamed_summary.triangles));

    // Samples on the held mesh, with upper bounds from the reservoir.
    SampleIndex samples, far_samples;
    samples.values = far_samples.values = values;
    std::copy(triangles.xyz.begin(), triangles.xyz.begin() + 3, samples.origin);
    {
        double density = held_summary.area > 0 ? double(held_samples) / held_summary.area : 0;
        size_t n_tri = triangles.xyz.size() / 9;
        float own[6] = {};
        for (size_t i = 0; i < n_tri && density > 0; ++i) {
            const float* t = &triangles.xyz[9 * i];
            Rng rng = triangle_rng(options.seed, kSaltMemorySamples, i);
            uint64_t k = samples_for(triangle_area(t), density, rng);
            for (uint64_t j = 0; j < k; ++j) {
                double p[3], bary[3];
                point_in_triangle(t, rng, p, bary);
                if (values) interpolate(&triangles.corner_values[3 * size_t(values) * i], values, bary, own);
                samples.add(p, own);
            }
        }
        std::vector<uint32_t> order;
        std::vector<BvhNode> points = build_bvh(
            static_cast<uint32_t>(reservoir.size() / 3),
            [&](uint32_t i, float lo[3], float hi[3]) {
                for (int x = 0; x < 3; ++x) lo[x] = hi[x] = reservoir[3 * size_t{i} + x];
            },
            8, order);
        permute(reservoir, order, 3);
        if (values) permute(reservoir_values, order, size_t(values));
        size_t n = samples.xyz.size() / 3;
        std::vector<double> bound2(n);
        samples.other.resize(n * size_t(values));
        for (size_t i = 0; i < n; ++i) {
            double p[3];
            samples.position(i, p);
            uint32_t nearest = 0;
            bound2[i] = bvh_nearest(
                points, p, kInf,
                [&](uint32_t r) {
                    double d[3] = {p[0] - reservoir[3 * size_t{r}], p[1] - reservoir[3 * size_t{r} + 1],
                                   p[2] - reservoir[3 * size_t{r} + 2]};
                    return dot3(d, d);
                },
                &nearest);
            if (values)
                std::memcpy(&samples.other[values * i], &reservoir_values[values * size_t{nearest}],
                            values * sizeof(float));
            if (options.progress && i % 65536 == 0) options.progress("bounding samples", i, n);
        }
        reservoir = std::vector<float>();  // freed before pass 2 (`= {}` would keep it)
        reservoir_values = std::vector<float>();
        // Samples farther from the streamed surface than a few of its triangles' size would each
        // meet every streamed triangle within reach, one at a time (a plane 0.25 above a grid of
        // 210 k triangles took 564 s): they meet chunks of triangles through a BVH instead.
        const double typical = streamed_summary.triangles > 0
                                   ? std::sqrt(2 * streamed_summary.area / double(streamed_summary.triangles))
                                   : 0;
        const double far2 = (kFarFactor * typical) * (kFarFactor * typical);
        if (std::any_of(bound2.begin(), bound2.end(), [&](double bound) { return bound > far2; })) {
            SampleIndex near;
            near.values = values;
            std::copy(samples.origin, samples.origin + 3, near.origin);
            std::copy(samples.origin, samples.origin + 3, far_samples.origin);
            std::vector<double> near_bound2, far_bound2;
            for (size_t i = 0; i < n; ++i) {
                const bool far = bound2[i] > far2;
                (far ? far_samples : near).add_from(samples, i);
                (far ? far_bound2 : near_bound2).push_back(bound2[i]);
            }
            samples = std::move(near);
            bound2 = std::move(near_bound2);
            far_samples.build(std::move(far_bound2));
        }
        samples.build(std::move(bound2));
    }
    triangles.build();

    // Pass 2: samples on the streamed mesh against the held triangles, and the held samples'
    // running minimum against each streamed triangle.
    StatsAccumulator streamed_stats;
    AttributeAccumulator streamed_attributes{layout, {}, {}};
    {
        double density = streamed_summary.area > 0 ? double(streamed_samples) / streamed_summary.area : 0;
        MeshSummary check;
        TriangleIndex chunk;  // for the far samples
        chunk.values = values;
        float chunk_lo[3], chunk_hi[3];
        auto flush = [&] {
            if (chunk.xyz.empty()) return;
            chunk.build();
            far_samples.update(chunk, chunk_lo, chunk_hi);
            chunk.xyz.clear();
            chunk.corner_values.clear();
        };
        float own[6] = {}, other[6] = {};
        stream_mesh(streamed.open(), layout, check, nullptr, options, "pass 2: " + streamed.name,
                    [&](uint64_t index, const float* t, const float* corners) {
                        Rng rng = triangle_rng(options.seed, kSaltStreamSamples, index);
                        uint64_t k = density > 0 ? samples_for(triangle_area(t), density, rng) : 0;
                        for (uint64_t j = 0; j < k; ++j) {
                            double p[3], bary[3];
                            point_in_triangle(t, rng, p, bary);
                            if (!values) {
                                streamed_stats.add(triangles.nearest_dist2(p));
                                continue;
                            }
                            streamed_stats.add(triangles.nearest_dist2(p, kInf, other));
                            interpolate(corners, values, bary, own);
                            streamed_attributes.add(own, other);
                        }
                        float lo[3], hi[3];
                        for (int x = 0; x < 3; ++x) {
                            lo[x] = std::min({t[x], t[3 + x], t[6 + x]});
                            hi[x] = std::max({t[x], t[3 + x], t[6 + x]});
                        }
                        samples.update(t, corners, lo, hi);
                        if (far_samples.xyz.empty()) return;
                        // Consecutive triangles of a mesh file are mostly near each other: a
                        // chunk's box stays small.
                        const bool first = chunk.xyz.empty();
                        for (int x = 0; x < 3; ++x) {
                            chunk_lo[x] = first ? lo[x] : std::min(chunk_lo[x], lo[x]);
                            chunk_hi[x] = first ? hi[x] : std::max(chunk_hi[x], hi[x]);
                        }
                        chunk.xyz.insert(chunk.xyz.end(), t, t + 9);
                        if (values)
                            chunk.corner_values.insert(chunk.corner_values.end(), corners, corners + 3 * values);
                        if (chunk.xyz.size() == 9 * kChunkTriangles) flush();
                    });
        flush();
        if (check.triangles != streamed_summary.triangles || check.area != streamed_summary.area)
            throw io::Error(streamed.name, "changed between the two passes (" +
                                               std::to_string(streamed_summary.triangles) + " triangles, then " +
                                               std::to_string(check.triangles) + ")");
    }
    StatsAccumulator held_stats;
    for (double d2 : samples.best2) held_stats.add(d2);
    for (double d2 : far_samples.best2) held_stats.add(d2);
    AttributeAccumulator held_attributes{layout, {}, {}};
    for (const SampleIndex* index : {&samples, &far_samples})
        for (size_t i = 0; values && i < index->own.size() / values; ++i)
            held_attributes.add(&index->own[values * i], &index->other[values * i]);

    CompareResult r;
    r.a = hold_a ? held_summary : streamed_summary;
    r.b = hold_a ? streamed_summary : held_summary;
    r.a_to_b = hold_a ? held_stats.stats() : streamed_stats.stats();
    r.b_to_a = hold_a ? streamed_stats.stats() : held_stats.stats();
    r.diagonal = r.a.diagonal();
    if (options.attributes) {
        const AttributeAccumulator& from_a = hold_a ? held_attributes : streamed_attributes;
        const AttributeAccumulator& from_b = hold_a ? streamed_attributes : held_attributes;
        AttributeErrors e;
        e.color = layout.color;
        e.normal = layout.normal;
        e.color_a_to_b = from_a.color.stats();
        e.color_b_to_a = from_b.color.stats();
        e.normal_a_to_b = from_a.normal.stats();
        e.normal_b_to_a = from_b.normal.stats();
        r.attributes = e;
    }
    return r;
}

}  // namespace meshstream::compare
