// Bounded-memory welding: a hash table within the budget, an external sort beyond it (see
// weld.hpp for the costs). One template serves both keys: positions, or vertex ids.
#include "io/weld.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/hash.hpp"
#include "io/position_key.hpp"
#include "io/record_sort.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <optional>
#include <vector>

namespace meshstream::io {
namespace {

// Key = bit pattern of the position, then the corner's attribute record (N bytes, zero padded
// past the layout's size): corners of one position with different attributes (UV or normal
// seams) stay different vertices.
template <size_t N>
struct PositionVertex {
    uint32_t pos[3];
    uint8_t used;
    std::array<std::byte, N> attr;
    static constexpr bool kHasId = false;
    static constexpr size_t kAttrBytes = N;
    void set_id(uint64_t) {}
    bool same_key(const PositionVertex& o) const {
        return pos[0] == o.pos[0] && pos[1] == o.pos[1] && pos[2] == o.pos[2] && attr == o.attr;
    }
    bool key_less(const PositionVertex& o) const {
        if (pos[0] != o.pos[0]) return pos[0] < o.pos[0];
        if (pos[1] != o.pos[1]) return pos[1] < o.pos[1];
        if (pos[2] != o.pos[2]) return pos[2] < o.pos[2];
        return attr < o.attr;
    }
    uint64_t hash() const {
        uint64_t h = mix64((uint64_t{pos[0]} << 32 | pos[1]) ^ mix64(pos[2] + 0x9e3779b97f4a7c15ULL));
        if constexpr (N > 0) h = mix64(h ^ hash_bytes(attr.data(), N));
        return h;
    }
};

// Key = (vertex id, position bits, attributes): producers' ids, kept apart if they ever
// disagree on position or attributes.
template <size_t N>
struct IdVertex {
    uint64_t id;
    uint32_t pos[3];
    uint8_t used;
    std::array<std::byte, N> attr;
    static constexpr bool kHasId = true;
    static constexpr size_t kAttrBytes = N;
    void set_id(uint64_t v) { id = v; }
    bool same_key(const IdVertex& o) const {
        return id == o.id && pos[0] == o.pos[0] && pos[1] == o.pos[1] && pos[2] == o.pos[2] && attr == o.attr;
    }
    bool key_less(const IdVertex& o) const {
        if (id != o.id) return id < o.id;
        if (pos[0] != o.pos[0]) return pos[0] < o.pos[0];
        if (pos[1] != o.pos[1]) return pos[1] < o.pos[1];
        if (pos[2] != o.pos[2]) return pos[2] < o.pos[2];
        return attr < o.attr;
    }
    uint64_t hash() const {
        uint64_t h = mix64(id ^ mix64((uint64_t{pos[0]} << 32 | pos[1]) + pos[2]));
        if constexpr (N > 0) h = mix64(h ^ hash_bytes(attr.data(), N));
        return h;
    }
};

struct CornerId {  // second sort of the out-of-core path
    uint64_t corner;
    uint32_t id;
    uint32_t pad;
};
struct CornerIdLess {
    bool operator()(const CornerId& a, const CornerId& b) const { return a.corner < b.corner; }
};

constexpr size_t kReadBlockRecords = 8192;

}  // namespace

struct Welder::Core {
    virtual ~Core() = default;
    virtual void add(const TriangleChunk& chunk) = 0;
    virtual void finish() = 0;
    virtual size_t next_vertices(std::span<float> xyz, std::span<std::byte> attributes) = 0;
    virtual size_t next_indices(std::span<uint32_t> out) = 0;
    uint64_t vertices = 0, triangles = 0;
    bool out_of_core = false;
};

namespace {

struct EmptyCore : Welder::Core {
    void add(const TriangleChunk&) override {}
    void finish() override {}
    size_t next_vertices(std::span<float>, std::span<std::byte>) override { return 0; }
    size_t next_indices(std::span<uint32_t>) override { return 0; }
};

template <class V>
class WeldCore : public Welder::Core {
public:
    WeldCore(uint64_t budget_bytes, std::string tmpdir, std::string name, const CornerLayout& layout)
        : budget_(budget_bytes), tmpdir_(std::move(tmpdir)), name_(std::move(name)), layout_(layout) {
        assert(layout_.bytes() <= V::kAttrBytes);
        spool_ = std::make_unique<TempFile>(tmpdir_, "meshstream-corners");
    }

    void add(const TriangleChunk& chunk) override {
        const size_t n = chunk.size();
        auto xyz = chunk.xyz();
        auto ids = chunk.vertex_ids();
        corners_.resize(3 * n);
        for (size_t c = 0; c < 3 * n; ++c) {
            V& v = corners_[c];
            std::memset(&v, 0, sizeof v);
            for (int a = 0; a < 3; ++a) v.pos[a] = position_bits(xyz[3 * c + a]);
            if constexpr (V::kAttrBytes > 0) layout_.pack(chunk, c / 3, int(c % 3), v.attr.data());
            if constexpr (V::kHasId) v.set_id(ids.empty() ? 0 : ids[c]);
            v.used = 1;
        }
        triangles += n;
        if (!sorter_) {
            for (size_t c = 0; c < corners_.size() && !sorter_; ++c)
                if (!insert(corners_[c])) switch_to_sort();
            if (!sorter_) {
                spool_->write(corners_.data(), corners_.size() * sizeof(V));
                spooled_ += corners_.size();
                return;
            }
        }
        for (const V& v : corners_) sorter_->push({v, next_corner_++});
    }

    void finish() override {
        if (!sorter_) {
            order_.reserve(used_);
            for (size_t s = 0; s < table_.size(); ++s)
                if (table_[s].v.used) order_.push_back(static_cast<uint32_t>(s));
            std::sort(order_.begin(), order_.end(),
                      [&](uint32_t a, uint32_t b) { return table_[a].v.key_less(table_[b].v); });
            for (size_t r = 0; r < order_.size(); ++r) table_[order_[r]].out = static_cast<uint32_t>(r);
            vertices = order_.size();
            return;
        }
        out_of_core = true;
        sorter_->finish_input(budget_ / 2);
        back_ = std::make_unique<RecordSorter<CornerId, CornerIdLess>>(budget_ / 2, tmpdir_);
        vertex_file_ = std::make_unique<TempFile>(tmpdir_, "meshstream-welded");
        Record r;
        std::optional<V> prev;
        uint64_t id = 0;
        while (sorter_->next(r)) {
            if (!prev || !prev->same_key(r.v)) {
                if (prev) ++id;
                if (id > 0xffffffffULL) throw Error(name_, "more than 2^32 - 1 distinct vertices");
                vertex_file_->write(&r.v, sizeof(V));
                prev = r.v;
            }
            back_->push({r.corner, static_cast<uint32_t>(id), 0});
        }
        vertices = prev ? id + 1 : 0;
        sorter_.reset();
        vertex_file_->flush();
        back_->finish_input(budget_ / 2);
    }

    size_t next_vertices(std::span<float> xyz, std::span<std::byte> attributes) override {
        const size_t rec = layout_.bytes();
        size_t fit = xyz.size() / 3;
        if (rec > 0) fit = std::min(fit, attributes.size() / rec);
        size_t n = static_cast<size_t>(std::min<uint64_t>(fit, vertices - vertices_read_));
        if (n == 0) return 0;
        if (out_of_core) {
            vertex_block_.resize(n);
            vertex_file_->read_at(vertices_read_ * sizeof(V), vertex_block_.data(), n * sizeof(V));
            for (size_t i = 0; i < n; ++i)
                to_welded(vertex_block_[i], &xyz[3 * i], rec > 0 ? &attributes[rec * i] : nullptr);
        } else {
            for (size_t i = 0; i < n; ++i)
                to_welded(table_[order_[vertices_read_ + i]].v, &xyz[3 * i], rec > 0 ? &attributes[rec * i] : nullptr);
        }
        vertices_read_ += n;
        return n;
    }

    size_t next_indices(std::span<uint32_t> out) override {
        size_t want = out.size() / 3 * 3;
        size_t n = 0;
        if (out_of_core) {
            CornerId c;
            while (n < want && back_->next(c)) out[n++] = c.id;
            return n;
        }
        while (n < want && corners_read_ < spooled_) {
            if (block_pos_ == block_.size()) {
                size_t k = static_cast<size_t>(std::min<uint64_t>(kReadBlockRecords, spooled_ - corners_read_));
                block_.resize(k);
                spool_->read_at(corners_read_ * sizeof(V), block_.data(), k * sizeof(V));
                block_pos_ = 0;
            }
            size_t take = std::min(want - n, block_.size() - block_pos_);
            for (size_t i = 0; i < take; ++i) out[n + i] = table_[find(block_[block_pos_ + i])].out;
            block_pos_ += take;
            corners_read_ += take;
            n += take;
        }
        return n;
    }

private:
    struct Entry {
        V v;
        uint32_t out;
    };
    struct Record {
        V v;
        uint64_t corner;
    };
    struct RecordLess {
        bool operator()(const Record& a, const Record& b) const {
            if (a.v.key_less(b.v)) return true;
            if (b.v.key_less(a.v)) return false;
            return a.corner < b.corner;
        }
    };

    void to_welded(const V& v, float* xyz, std::byte* attributes) const {
        for (int a = 0; a < 3; ++a) xyz[a] = std::bit_cast<float>(v.pos[a]);
        if constexpr (V::kAttrBytes > 0)
            if (attributes) std::memcpy(attributes, v.attr.data(), layout_.bytes());
    }

    // Inserts v's key if absent; false when the table would outgrow the budget.
    bool insert(const V& v) {
        if ((used_ + 1) * 5 > table_.size() * 4 && !grow()) return false;
        size_t mask = table_.size() - 1;
        for (size_t h = v.hash() & mask;; h = (h + 1) & mask) {
            Entry& e = table_[h];
            if (!e.v.used) {
                e.v = v;
                ++used_;
                return true;
            }
            if (e.v.same_key(v)) return true;
        }
    }

    size_t find(const V& v) const {
        size_t mask = table_.size() - 1;
        for (size_t h = v.hash() & mask;; h = (h + 1) & mask)
            if (table_[h].v.same_key(v)) return h;
    }

    // Doubles the table when old + new (and the final rank array) fit the budget.
    bool grow() {
        size_t cap = table_.empty() ? 4096 : 2 * table_.size();
        uint64_t need =
            uint64_t{cap} * sizeof(Entry) + std::max<uint64_t>(table_.size() * sizeof(Entry), cap / 5 * 4 * 4);
        if (need > budget_ || cap > (size_t{1} << 32)) return false;
        std::vector<Entry> old(cap);
        old.swap(table_);
        used_ = 0;
        for (const Entry& e : old)
            if (e.v.used) insert(e.v);
        return true;
    }

    // The table is full: free it, and replay the corners spooled so far into the sorter.
    void switch_to_sort() {
        std::vector<Entry>().swap(table_);
        used_ = 0;
        sorter_ = std::make_unique<RecordSorter<Record, RecordLess>>(budget_, tmpdir_);
        std::vector<V> block;
        for (uint64_t done = 0; done < spooled_;) {
            size_t k = static_cast<size_t>(std::min<uint64_t>(kReadBlockRecords, spooled_ - done));
            block.resize(k);
            spool_->read_at(done * sizeof(V), block.data(), k * sizeof(V));
            for (const V& v : block) sorter_->push({v, next_corner_++});
            done += k;
        }
        spool_.reset();
        spooled_ = 0;
    }

    uint64_t budget_;
    std::string tmpdir_, name_;
    CornerLayout layout_;
    std::vector<V> corners_;  // the current chunk's corners
    // In-memory path.
    std::vector<Entry> table_;
    size_t used_ = 0;
    std::unique_ptr<TempFile> spool_;
    uint64_t spooled_ = 0;
    std::vector<uint32_t> order_;
    uint64_t vertices_read_ = 0, corners_read_ = 0;
    std::vector<V> block_;
    size_t block_pos_ = 0;
    // Out-of-core path.
    std::unique_ptr<RecordSorter<Record, RecordLess>> sorter_;
    uint64_t next_corner_ = 0;
    std::unique_ptr<RecordSorter<CornerId, CornerIdLess>> back_;
    std::unique_ptr<TempFile> vertex_file_;
    std::vector<V> vertex_block_;
};

}  // namespace

namespace {

// The core whose records hold `layout`'s corner record: the smallest of the sizes below.
template <template <size_t> class V>
std::unique_ptr<Welder::Core> make_core(uint64_t budget, const std::string& tmpdir, const std::string& name,
                                        const CornerLayout& layout) {
    const size_t n = layout.bytes();
    if (n == 0) return std::make_unique<WeldCore<V<0>>>(budget, tmpdir, name, layout);
    if (n <= 16) return std::make_unique<WeldCore<V<16>>>(budget, tmpdir, name, layout);
    if (n <= 32) return std::make_unique<WeldCore<V<32>>>(budget, tmpdir, name, layout);
    if (n <= 64) return std::make_unique<WeldCore<V<64>>>(budget, tmpdir, name, layout);
    if (n <= 128) return std::make_unique<WeldCore<V<128>>>(budget, tmpdir, name, layout);
    if (n <= Welder::kMaxAttributeBytes) return std::make_unique<WeldCore<V<256>>>(budget, tmpdir, name, layout);
    throw Error(name, std::to_string(n) + " bytes of vertex attributes per corner, more than the " +
                          std::to_string(Welder::kMaxAttributeBytes) +
                          " an indexed writer keeps (drop some with " + mention(Setting::kDrop) + " extra)");
}

}  // namespace

Welder::Welder(uint64_t budget_bytes, std::string tmpdir, std::string name, const Channels& channels)
    : budget_bytes_(budget_bytes), tmpdir_(std::move(tmpdir)), name_(std::move(name)), layout_(channels) {
    if (layout_.bytes() > kMaxAttributeBytes) make_core<PositionVertex>(0, tmpdir_, name_, layout_);  // throws
}

Welder::~Welder() = default;

void Welder::add(const TriangleChunk& chunk) {
    if (chunk.empty()) return;
    if (!core_) {
        if (chunk.channels().vertex_id)
            core_ = make_core<IdVertex>(budget_bytes_, tmpdir_, name_, layout_);
        else
            core_ = make_core<PositionVertex>(budget_bytes_, tmpdir_, name_, layout_);
    }
    core_->add(chunk);
}

void Welder::finish() {
    if (!core_) core_ = std::make_unique<EmptyCore>();
    core_->finish();
}

uint64_t Welder::vertex_count() const { return core_->vertices; }
uint64_t Welder::triangle_count() const { return core_->triangles; }
bool Welder::out_of_core() const { return core_->out_of_core; }
size_t Welder::next_vertices(std::span<float> xyz, std::span<std::byte> attributes) {
    return core_->next_vertices(xyz, attributes);
}
size_t Welder::next_indices(std::span<uint32_t> out) { return core_->next_indices(out); }

}  // namespace meshstream::io
