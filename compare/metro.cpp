// Metro-style error between two meshes (Cignoni, Rocchini & Scopigno 1998), streaming the
// larger one. See metro.hpp for the method and its memory bound. Spatial indices are BVHs
// built by median split on the longest centroid axis (leaf 4 triangles / 8 samples); distances
// use Ericson's closest point on a triangle (Real-Time Collision Detection, §5.1.5) in double.
#include "compare/metro.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/random.hpp"

#include <algorithm>
#include <array>
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

// A uniformly distributed point on triangle t (Osada et al. 2002: sqrt of r1).
void point_in_triangle(const float* t, Rng& rng, double p[3]) {
    double s = std::sqrt(rng.uniform()), r2 = rng.uniform();
    double wa = 1 - s, wb = s * (1 - r2), wc = s * r2;
    for (int a = 0; a < 3; ++a) p[a] = wa * t[a] + wb * t[3 + a] + wc * t[6 + a];
}

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

double segment_dist2(const double p[3], const double a[3], const double b[3]) {
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    double len2 = dot3(ab, ab), t = len2 > 0 ? std::clamp(dot3(ap, ab) / len2, 0.0, 1.0) : 0.0;
    double d[3] = {ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]};
    return dot3(d, d);
}

// Squared distance from p to triangle t (9 floats), Ericson §5.1.5 by Voronoi regions. A
// degenerate triangle (zero area) falls back to its three edges, where the region divisions
// would be 0/0.
double point_triangle_dist2(const double p[3], const float* t) {
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
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) return dist2_to(a);
    double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) return dist2_to(b);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        if (d1 - d3 <= 0) return std::min({segment_dist2(p, a, b), segment_dist2(p, b, c), segment_dist2(p, a, c)});
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + v * ab[k];
        return dist2_to(q);
    }
    double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) return dist2_to(c);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        if (d2 - d6 <= 0) return std::min({segment_dist2(p, a, b), segment_dist2(p, b, c), segment_dist2(p, a, c)});
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + w * ac[k];
        return dist2_to(q);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double den = (d4 - d3) + (d5 - d6);
        if (den <= 0) return std::min({segment_dist2(p, a, b), segment_dist2(p, b, c), segment_dist2(p, a, c)});
        double w = (d4 - d3) / den;
        for (int k = 0; k < 3; ++k) q[k] = b[k] + w * (c[k] - b[k]);
        return dist2_to(q);
    }
    double sum = va + vb + vc;
    if (!(sum > 0)) return std::min({segment_dist2(p, a, b), segment_dist2(p, b, c), segment_dist2(p, a, c)});
    double v = vb / sum, w = vc / sum;
    for (int k = 0; k < 3; ++k) q[k] = a[k] + ab[k] * v + ac[k] * w;
    return dist2_to(q);
}

// ---- BVH over boxes ------------------------------------------------------------------------

struct BvhNode {
    float lo[3], hi[3];
    uint32_t first;  // leaf: first primitive; inner: index of the left child (right = first + 1)
    uint32_t count;  // primitives in a leaf, 0 for an inner node
};

// Builds a BVH over n primitives whose boxes `box(i, lo, hi)` gives. Returns the nodes and
// writes the primitive order into `order` (the caller permutes its data by it).
template <class BoxFn>
std::vector<BvhNode> build_bvh(uint32_t n, BoxFn box, uint32_t leaf_size, std::vector<uint32_t>& order) {
    std::vector<BvhNode> nodes;
    order.resize(n);
    for (uint32_t i = 0; i < n; ++i) order[i] = i;
    if (n == 0) return nodes;
    std::vector<float> centroid(size_t{3} * n);
    for (uint32_t i = 0; i < n; ++i) {
        float lo[3], hi[3];
        box(i, lo, hi);
        for (int a = 0; a < 3; ++a) centroid[3 * size_t{i} + a] = 0.5f * (lo[a] + hi[a]);
    }
    nodes.reserve(2 * (size_t{n} / leaf_size + 1));
    nodes.push_back({});
    struct Job {
        uint32_t node, begin, end;
    };
    std::vector<Job> stack{{0, 0, n}};
    while (!stack.empty()) {
        Job job = stack.back();
        stack.pop_back();
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t k = job.begin; k < job.end; ++k) {
            float blo[3], bhi[3];
            box(order[k], blo, bhi);
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], blo[a]);
                hi[a] = std::max(hi[a], bhi[a]);
                float c = centroid[3 * size_t{order[k]} + a];
                clo[a] = std::min(clo[a], c);
                chi[a] = std::max(chi[a], c);
            }
        }
        BvhNode& node = nodes[job.node];
        std::memcpy(node.lo, lo, sizeof lo);
        std::memcpy(node.hi, hi, sizeof hi);
        if (job.end - job.begin <= leaf_size) {
            node.first = job.begin;
            node.count = job.end - job.begin;
            continue;
        }
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
        uint32_t mid = job.begin + (job.end - job.begin) / 2;
        std::nth_element(
            order.begin() + job.begin, order.begin() + mid, order.begin() + job.end,
            [&](uint32_t x, uint32_t y) { return centroid[3 * size_t{x} + axis] < centroid[3 * size_t{y} + axis]; });
        uint32_t left = static_cast<uint32_t>(nodes.size());
        node.first = left;
        node.count = 0;
        nodes.push_back({});  // invalidates `node`
        nodes.push_back({});
        stack.push_back({left, job.begin, mid});
        stack.push_back({left + 1, mid, job.end});
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

// Nearest primitive to p: returns the smallest leaf_dist2(i) below `best2`, or best2.
template <class LeafFn>
double bvh_nearest(const std::vector<BvhNode>& nodes, const double p[3], double best2, LeafFn leaf_dist2) {
    if (nodes.empty()) return best2;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& n = nodes[stack[--top]];
        if (box_dist2(n, p) >= best2) continue;
        if (n.count) {
            for (uint32_t i = n.first; i < n.first + n.count; ++i) best2 = std::min(best2, leaf_dist2(i));
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

// Triangles held in memory, with their BVH.
struct TriangleIndex {
    std::vector<float> xyz;  // 9 floats per triangle, in BVH order
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
    }
    double nearest_dist2(const double p[3]) const {
        return bvh_nearest(nodes, p, kInf, [&](uint32_t i) { return point_triangle_dist2(p, &xyz[9 * size_t{i}]); });
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
    std::vector<float> xyz;     // 3 floats per sample relative to origin, in BVH order
    std::vector<double> best2;  // running minimum squared distance
    std::vector<BvhNode> nodes;

    void add(const double p[3]) {
        xyz.insert(xyz.end(), {float(p[0] - origin[0]), float(p[1] - origin[1]), float(p[2] - origin[2])});
    }
    void add_relative(const float* rel) { xyz.insert(xyz.end(), rel, rel + 3); }
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
    }

    // Lowers best2 of every sample that triangle t (absolute bounding box abs_lo..abs_hi) is
    // closer to.
    void update(const float* t, const float abs_lo[3], const float abs_hi[3]) {
        lower_within(abs_lo, abs_hi,
                     [&](const double p[3], double so_far) { return std::min(so_far, point_triangle_dist2(p, t)); });
    }
    // The same for every triangle of `chunk` (abs_lo..abs_hi bounds them all), through its BVH:
    // for samples far from the streamed surface, which a triangle at a time would meet once for
    // every triangle within reach.
    void update(const TriangleIndex& chunk, const float abs_lo[3], const float abs_hi[3]) {
        lower_within(abs_lo, abs_hi, [&](const double p[3], double so_far) {
            return bvh_nearest(chunk.nodes, p, so_far,
                               [&](uint32_t k) { return point_triangle_dist2(p, &chunk.xyz[9 * size_t{k}]); });
        });
    }

private:
    // Calls best2[i] = lower(p_i, best2[i]) for every sample i whose box reaches abs_lo..abs_hi
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
                best2[i] = lower(p, best2[i]);
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

// Reads the whole of `source` through `fn(triangle_index, tri)` for finite triangles; fills
// the summary's counts, area and bounds (edges when `edges` is given).
template <class Fn>
void stream_mesh(const MeshSource& source, MeshSummary& summary, EdgeCounter* edges, const CompareOptions& options,
                 std::string_view phase, Fn fn) {
    std::unique_ptr<io::Reader> reader = source.open();
    std::optional<uint64_t> total = reader->triangle_count();
    io::TriangleChunk chunk;
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
            fn(index, tri);
        }
        if (options.progress) options.progress(phase, index, total);
    }
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

class MemoryReader final : public io::Reader {
public:
    explicit MemoryReader(std::shared_ptr<const std::vector<float>> xyz) : xyz_(std::move(xyz)) {
        header_.triangle_count = xyz_->size() / 9;
    }
    bool next(io::TriangleChunk& chunk) override {
        chunk.clear();
        size_t n = std::min(chunk.capacity(), xyz_->size() / 9 - pos_);
        std::memcpy(chunk.xyz_storage(), xyz_->data() + 9 * pos_, n * 9 * sizeof(float));
        chunk.resize(n);
        pos_ += n;
        return n > 0;
    }

private:
    std::shared_ptr<const std::vector<float>> xyz_;
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

MeshSource memory_source(std::string name, std::vector<float> xyz) {
    assert(xyz.size() % 9 == 0);
    MeshSource s;
    s.name = std::move(name);
    auto data = std::make_shared<const std::vector<float>>(std::move(xyz));
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

CompareResult compare_meshes(const MeshSource& a, const MeshSource& b, const CompareOptions& options) {
    // Which one to hold: the smaller by header count (or a PLY's face count) when both are
    // known, else B. A stream cannot be read twice (nor opened once just for its count), so it
    // is always the held one.
    if (a.once && b.once)
        throw io::Error(b.name, "compare cannot stream both meshes (stdin or pipes): one of them is read twice");
    bool hold_a = a.once;
    if (!a.once && !b.once) {
        auto count = [](const MeshSource& m) {
            const std::unique_ptr<io::Reader> reader = m.open();
            const io::MeshHeader& h = reader->header();
            return h.triangle_count ? h.triangle_count : h.triangle_estimate;
        };
        const std::optional<uint64_t> count_a = count(a), count_b = count(b);
        hold_a = count_a && count_b && *count_a < *count_b;
    }
    const MeshSource& held = hold_a ? a : b;
    const MeshSource& streamed = hold_a ? b : a;

    MeshSummary held_summary, streamed_summary;
    held_summary.name = held.name;
    held_summary.in_memory = true;
    streamed_summary.name = streamed.name;

    // The held mesh: triangles, edges, and later its samples.
    TriangleIndex triangles;
    {
        EdgeCounter edges(options.memory_budget_bytes, options.tmpdir);
        stream_mesh(held, held_summary, &edges, options, "reading " + held.name,
                    [&](uint64_t, const float* t) { triangles.xyz.insert(triangles.xyz.end(), t, t + 9); });
        held_summary.edges = edges.finish();
    }
    if (triangles.xyz.empty()) throw io::Error(held.name, "holds no (finite) triangles; nothing to compare");
    uint64_t held_samples = options.samples.value_or(default_sample_count(held_summary.triangles));

    // Pass 1 over the streamed mesh: counts, area, edges, and a reservoir of its vertices
    // (Vitter's algorithm R), whose distances to the held samples bound the true distances
    // from above before pass 2.
    std::vector<float> reservoir;
    size_t reservoir_capacity = static_cast<size_t>(std::clamp<uint64_t>(held_samples, 1024, 10'000'000));
    {
        EdgeCounter edges(options.memory_budget_bytes, options.tmpdir);
        uint64_t seen = 0;
        stream_mesh(streamed, streamed_summary, &edges, options, "pass 1: " + streamed.name,
                    [&](uint64_t index, const float* t) {
                        Rng rng = triangle_rng(options.seed, kSaltReservoir, index);
                        const float* corner = t + 3 * (rng.next() % 3);
                        if (seen < reservoir_capacity) {
                            reservoir.insert(reservoir.end(), corner, corner + 3);
                        } else {
                            uint64_t slot = rng.next() % (seen + 1);
                            if (slot < reservoir_capacity) std::memcpy(&reservoir[3 * slot], corner, 3 * sizeof(float));
                        }
                        ++seen;
                    });
        streamed_summary.edges = edges.finish();
    }
    if (reservoir.empty()) throw io::Error(streamed.name, "holds no (finite) triangles; nothing to compare");
    uint64_t streamed_samples = options.samples.value_or(default_sample_count(streamed_summary.triangles));

    // Samples on the held mesh, with upper bounds from the reservoir.
    SampleIndex samples, far_samples;
    std::copy(triangles.xyz.begin(), triangles.xyz.begin() + 3, samples.origin);
    {
        double density = held_summary.area > 0 ? double(held_samples) / held_summary.area : 0;
        size_t n_tri = triangles.xyz.size() / 9;
        for (size_t i = 0; i < n_tri && density > 0; ++i) {
            const float* t = &triangles.xyz[9 * i];
            Rng rng = triangle_rng(options.seed, kSaltMemorySamples, i);
            uint64_t k = samples_for(triangle_area(t), density, rng);
            for (uint64_t j = 0; j < k; ++j) {
                double p[3];
                point_in_triangle(t, rng, p);
                samples.add(p);
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
        size_t n = samples.xyz.size() / 3;
        std::vector<double> bound2(n);
        for (size_t i = 0; i < n; ++i) {
            double p[3];
            samples.position(i, p);
            bound2[i] = bvh_nearest(points, p, kInf, [&](uint32_t r) {
                double d[3] = {p[0] - reservoir[3 * size_t{r}], p[1] - reservoir[3 * size_t{r} + 1],
                               p[2] - reservoir[3 * size_t{r} + 2]};
                return dot3(d, d);
            });
            if (options.progress && i % 65536 == 0) options.progress("bounding samples", i, n);
        }
        reservoir = std::vector<float>();  // freed before pass 2 (`= {}` would keep it)
        // Samples farther from the streamed surface than a few of its triangles' size would each
        // meet every streamed triangle within reach, one at a time (a plane 0.25 above a grid of
        // 210 k triangles took 564 s): they meet chunks of triangles through a BVH instead.
        const double typical = streamed_summary.triangles > 0
                                   ? std::sqrt(2 * streamed_summary.area / double(streamed_summary.triangles))
                                   : 0;
        const double far2 = (kFarFactor * typical) * (kFarFactor * typical);
        if (std::any_of(bound2.begin(), bound2.end(), [&](double bound) { return bound > far2; })) {
            SampleIndex near;
            std::copy(samples.origin, samples.origin + 3, near.origin);
            std::copy(samples.origin, samples.origin + 3, far_samples.origin);
            std::vector<double> near_bound2, far_bound2;
            for (size_t i = 0; i < n; ++i) {
                const bool far = bound2[i] > far2;
                (far ? far_samples : near).add_relative(&samples.xyz[3 * i]);
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
    {
        double density = streamed_summary.area > 0 ? double(streamed_samples) / streamed_summary.area : 0;
        MeshSummary check;
        TriangleIndex chunk;  // for the far samples
        float chunk_lo[3], chunk_hi[3];
        auto flush = [&] {
            if (chunk.xyz.empty()) return;
            chunk.build();
            far_samples.update(chunk, chunk_lo, chunk_hi);
            chunk.xyz.clear();
        };
        stream_mesh(streamed, check, nullptr, options, "pass 2: " + streamed.name, [&](uint64_t index, const float* t) {
            Rng rng = triangle_rng(options.seed, kSaltStreamSamples, index);
            uint64_t k = density > 0 ? samples_for(triangle_area(t), density, rng) : 0;
            for (uint64_t j = 0; j < k; ++j) {
                double p[3];
                point_in_triangle(t, rng, p);
                streamed_stats.add(triangles.nearest_dist2(p));
            }
            float lo[3], hi[3];
            for (int x = 0; x < 3; ++x) {
                lo[x] = std::min({t[x], t[3 + x], t[6 + x]});
                hi[x] = std::max({t[x], t[3 + x], t[6 + x]});
            }
            samples.update(t, lo, hi);
            if (far_samples.xyz.empty()) return;
            // Consecutive triangles of a mesh file are mostly near each other: a chunk's box
            // stays small.
            const bool first = chunk.xyz.empty();
            for (int x = 0; x < 3; ++x) {
                chunk_lo[x] = first ? lo[x] : std::min(chunk_lo[x], lo[x]);
                chunk_hi[x] = first ? hi[x] : std::max(chunk_hi[x], hi[x]);
            }
            chunk.xyz.insert(chunk.xyz.end(), t, t + 9);
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

    CompareResult r;
    r.a = hold_a ? held_summary : streamed_summary;
    r.b = hold_a ? streamed_summary : held_summary;
    r.a_to_b = hold_a ? held_stats.stats() : streamed_stats.stats();
    r.b_to_a = hold_a ? streamed_stats.stats() : held_stats.stats();
    r.diagonal = r.a.diagonal();
    return r;
}

}  // namespace meshstream::compare
