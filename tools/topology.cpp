// Topology counts by external sorting of vertex keys and edge keys (see topology.hpp).
#include "tools/topology.hpp"

#include "io/record_sort.hpp"

#include <bit>
#include <tuple>

namespace meshstream::tools {
namespace {

struct VertexKey {
    uint64_t a, b;
    bool operator==(const VertexKey&) const = default;
    bool operator<(const VertexKey& o) const { return std::tie(a, b) < std::tie(o.a, o.b); }
};
struct VertexLess {
    bool operator()(const VertexKey& x, const VertexKey& y) const { return x < y; }
};
struct EdgeKey {
    VertexKey lo, hi;
    bool operator==(const EdgeKey&) const = default;
};
struct EdgeLess {
    bool operator()(const EdgeKey& x, const EdgeKey& y) const {
        return std::tie(x.lo, x.hi) < std::tie(y.lo, y.hi);
    }
};

uint64_t bits(float f) {
    uint32_t b = std::bit_cast<uint32_t>(f);
    return b == 0x80000000u ? 0u : b;  // -0.0 is +0.0
}

}  // namespace

struct TopologyCounter::Sorters {
    Sorters(uint64_t budget, const std::string& tmpdir) : vertices(budget / 3, tmpdir), edges(2 * budget / 3, tmpdir) {}
    io::RecordSorter<VertexKey, VertexLess> vertices;
    io::RecordSorter<EdgeKey, EdgeLess> edges;
};

TopologyCounter::TopologyCounter(uint64_t budget_bytes, std::string tmpdir)
    : sorters_(std::make_unique<Sorters>(budget_bytes, tmpdir)), budget_bytes_(budget_bytes), tmpdir_(std::move(tmpdir)) {}

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
            size_t corner = 3 * t + c;
            if (by_id_ && !ids.empty()) {
                k[c] = {ids[corner], 0};
            } else {
                const float* p = &xyz[3 * corner];
                k[c] = {bits(p[0]) << 32 | bits(p[1]), bits(p[2])};
            }
            sorters_->vertices.push(k[c]);
        }
        // A triangle with a repeated corner (a, b, b) is no surface element: its edge a–b, met
        // both ways, would otherwise count as two uses and make a manifold edge non-manifold.
        if (k[0] == k[1] || k[1] == k[2] || k[2] == k[0]) continue;
        for (int e = 0; e < 3; ++e) {
            const VertexKey& u = k[e];
            const VertexKey& v = k[(e + 1) % 3];
            sorters_->edges.push(u < v ? EdgeKey{u, v} : EdgeKey{v, u});
        }
    }
}

TopologyReport TopologyCounter::finish() {
    TopologyReport r;
    r.by_vertex_id = by_id_;
    sorters_->vertices.finish_input(budget_bytes_ / 3);
    VertexKey vk, prev_v{};
    bool first = true;
    while (sorters_->vertices.next(vk)) {
        if (first || !(vk == prev_v)) ++r.vertices;
        prev_v = vk;
        first = false;
    }
    sorters_->edges.finish_input(2 * budget_bytes_ / 3);
    EdgeKey ek, prev_e{};
    uint64_t run = 0;
    auto close_run = [&] {
        if (run == 0) return;
        ++r.edges;
        if (run == 1) ++r.boundary_edges;
        if (run > 2) ++r.non_manifold_edges;
    };
    while (sorters_->edges.next(ek)) {
        if (run > 0 && ek == prev_e) {
            ++run;
            continue;
        }
        close_run();
        prev_e = ek;
        run = 1;
    }
    close_run();
    return r;
}

}  // namespace meshstream::tools
