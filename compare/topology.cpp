// Topology counts by external sorting of vertex keys and edge keys (see topology.hpp).
#include "compare/topology.hpp"

#include "io/record_sort.hpp"

#include <tuple>

namespace meshstream::compare {
namespace {

struct VertexLess {
    bool operator()(const VertexKey& x, const VertexKey& y) const { return x < y; }
};
struct EdgeKey {
    VertexKey lo, hi;
    bool operator==(const EdgeKey&) const = default;
};
struct EdgeLess {
    bool operator()(const EdgeKey& x, const EdgeKey& y) const { return std::tie(x.lo, x.hi) < std::tie(y.lo, y.hi); }
};

}  // namespace

struct EdgeCounter::Sorter : io::RecordSorter<EdgeKey, EdgeLess> {
    using RecordSorter::RecordSorter;
};

EdgeCounter::EdgeCounter(uint64_t budget_bytes, std::string tmpdir)
    : sorter_(std::make_unique<Sorter>(budget_bytes, std::move(tmpdir))), budget_bytes_(budget_bytes) {}

EdgeCounter::~EdgeCounter() = default;

void EdgeCounter::add(const VertexKey (&k)[3]) {
    if (k[0] == k[1] || k[1] == k[2] || k[2] == k[0]) return;  // no surface element (see the header)
    for (int e = 0; e < 3; ++e) {
        const VertexKey& u = k[e];
        const VertexKey& v = k[(e + 1) % 3];
        sorter_->push(u < v ? EdgeKey{u, v} : EdgeKey{v, u});
    }
}

void EdgeCounter::add_triangle(const float* tri) {
    const VertexKey k[3] = {VertexKey::of(tri), VertexKey::of(tri + 3), VertexKey::of(tri + 6)};
    add(k);
}

bool EdgeCounter::spilled() const { return sorter_->spilled(); }

EdgeCounts EdgeCounter::finish() {
    EdgeCounts r;
    sorter_->finish_input(budget_bytes_);
    EdgeKey ek, prev{};
    uint64_t run = 0;
    auto close_run = [&] {
        if (run == 0) return;
        ++r.edges;
        if (run == 1) ++r.boundary_edges;
        if (run > 2) ++r.non_manifold_edges;
    };
    while (sorter_->next(ek)) {
        if (run > 0 && ek == prev) {
            ++run;
            continue;
        }
        close_run();
        prev = ek;
        run = 1;
    }
    close_run();
    return r;
}

struct TopologyCounter::Vertices : io::RecordSorter<VertexKey, VertexLess> {
    using RecordSorter::RecordSorter;
};

TopologyCounter::TopologyCounter(uint64_t budget_bytes, std::string tmpdir)
    : vertices_(std::make_unique<Vertices>(budget_bytes / 3, tmpdir)),
      edges_(budget_bytes - budget_bytes / 3, tmpdir),
      budget_bytes_(budget_bytes) {}

TopologyCounter::~TopologyCounter() = default;

void TopologyCounter::add(const io::TriangleChunk& chunk) {
    if (chunk.empty()) return;
    if (!decided_) {
        decided_ = true;
        by_id_ = chunk.channels().vertex_id;
    }
    auto xyz = chunk.xyz();
    auto ids = chunk.vertex_ids();
    for (size_t t = 0; t < chunk.size(); ++t) {
        VertexKey k[3];
        for (int c = 0; c < 3; ++c) {
            const size_t corner = 3 * t + c;
            k[c] = by_id_ && !ids.empty() ? VertexKey{ids[corner], 0} : VertexKey::of(&xyz[3 * corner]);
            vertices_->push(k[c]);
        }
        edges_.add(k);
    }
}

TopologyReport TopologyCounter::finish() {
    TopologyReport r;
    r.by_vertex_id = by_id_;
    vertices_->finish_input(budget_bytes_ / 3);
    VertexKey vk, prev{};
    bool first = true;
    while (vertices_->next(vk)) {
        if (first || !(vk == prev)) ++r.vertices;
        prev = vk;
        first = false;
    }
    const EdgeCounts e = edges_.finish();
    r.edges = e.edges;
    r.boundary_edges = e.boundary_edges;
    r.non_manifold_edges = e.non_manifold_edges;
    return r;
}

}  // namespace meshstream::compare
