// The order measure of `info --order` and decimate's "sorting would help" hint (definitions
// and error analysis in order.hpp). The vertex table is open addressing with linear probing
// and backward-shift deletion (Knuth TAOCP vol. 3, §6.4, Algorithm R), so dropping samples
// frees slots without tombstones.
#include "compare/order.hpp"

#include "io/error.hpp"
#include "io/hash.hpp"
#include "io/position_key.hpp"
#include "sort/radix.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace meshstream::compare {
namespace {

constexpr uint64_t kMinBudgetBytes = uint64_t{1} << 20;

using io::mix64;

}  // namespace

struct OrderMeter::Table {
    struct Slot {
        uint32_t p[3];
        uint32_t refs;  // samples using this vertex (per corner); 0 = empty slot
        uint64_t last;  // index of the last triangle seen with a corner here
    };
    std::vector<Slot> slots;
    size_t used = 0;
    size_t max_slots;

    explicit Table(size_t max) : slots(1024), max_slots(std::max<size_t>(max, 1024)) {}
    // Home slot: the hash scaled to the table size (Lemire's multiply-shift), so the table can
    // use its budget exactly rather than the largest power of two below it.
    size_t home(const uint32_t* p) const {
        uint64_t h = mix64((uint64_t{p[0]} << 32 | p[1]) ^ mix64(p[2] + 0x9E3779B97F4A7C15ull));
        return static_cast<size_t>((static_cast<unsigned __int128>(h) * slots.size()) >> 64);
    }
    size_t step(size_t i) const { return i + 1 == slots.size() ? 0 : i + 1; }
    Slot* find(const uint32_t* p) {
        for (size_t i = home(p);; i = step(i)) {
            Slot& s = slots[i];
            if (s.refs == 0) return nullptr;
            if (s.p[0] == p[0] && s.p[1] == p[1] && s.p[2] == p[2]) return &s;
        }
    }
    // True when `extra` more vertices fit at load <= 1/2, growing the table if allowed.
    bool reserve(size_t extra) {
        while (2 * (used + extra) > slots.size()) {
            if (slots.size() >= max_slots) return false;
            // Doubling, then one jump to the cap from at most half of it: the old copy never
            // exceeds half the cap.
            std::vector<Slot> old(4 * slots.size() <= max_slots ? 2 * slots.size() : max_slots);
            old.swap(slots);
            for (const Slot& s : old)
                if (s.refs) {
                    size_t i = home(s.p);
                    while (slots[i].refs) i = step(i);
                    slots[i] = s;
                }
        }
        return true;
    }
    // Adds one reference (inserting the vertex); precondition: reserve(1) succeeded.
    void ref(const uint32_t* p, uint64_t index) {
        for (size_t i = home(p);; i = step(i)) {
            Slot& s = slots[i];
            if (s.refs == 0) {
                std::memcpy(s.p, p, sizeof s.p);
                s.refs = 1;
                s.last = index;
                ++used;
                return;
            }
            if (s.p[0] == p[0] && s.p[1] == p[1] && s.p[2] == p[2]) {
                ++s.refs;
                s.last = index;
                return;
            }
        }
    }
    void unref(const uint32_t* p) {
        Slot* s = find(p);
        assert(s);
        if (--s->refs > 0) return;
        --used;
        // Backward-shift deletion: pull later members of the probe run into the hole.
        size_t hole = static_cast<size_t>(s - slots.data());
        for (size_t j = step(hole); slots[j].refs; j = step(j)) {
            size_t h = home(slots[j].p);
            // Slot j may move to the hole unless its home lies cyclically in (hole, j].
            bool home_between = hole <= j ? (h > hole && h <= j) : (h > hole || h <= j);
            if (!home_between) {
                slots[hole] = slots[j];
                hole = j;
            }
        }
        slots[hole].refs = 0;
    }
};

int OrderReport::best_axis() const {
    return static_cast<int>(std::min_element(descents.begin(), descents.end()) - descents.begin());
}

OrderMeter::OrderMeter(uint64_t memory_budget_bytes) : budget_bytes_(std::max(memory_budget_bytes, kMinBudgetBytes)) {
    // Half the budget for the table (while it grows it briefly holds its old copy too, at most
    // another quarter) and a fifth for the samples, reserved up front so they never
    // reallocate; finish() needs 16 bytes per sample more. A sample brings up to three new
    // vertices (48 bytes each at load 1/2), but on a closed mesh about half a vertex, so there
    // the samples run out first: exact up to about budget / 240 triangles (docs/cli.md).
    table_ = std::make_unique<Table>(budget_bytes_ / 2 / sizeof(Table::Slot));
    max_samples_ = budget_bytes_ / 5 / sizeof(Sample);
    samples_.reserve(max_samples_);
}

OrderMeter::~OrderMeter() = default;

void OrderMeter::add(const io::TriangleChunk& chunk) {
    auto xyz = chunk.xyz();
    for (size_t i = 0; i < chunk.size(); ++i) add_triangle(&xyz[9 * i]);
}

void OrderMeter::add_triangle(const float* xyz) {
    const uint64_t index = count_++;
    for (int a = 0; a < 3; ++a) {
        uint32_t key = sort::triangle_key(xyz, a);
        if (index > 0 && key < prev_key_[a]) ++descents_[a];
        prev_key_[a] = key;
    }
    uint32_t corner[9];
    for (int k = 0; k < 9; ++k) corner[k] = io::position_bits(xyz[k]);

    auto sampled = [&] { return (mix64(index) & ((uint64_t{1} << level_) - 1)) == 0; };
    if (!sampled()) {
        for (int v = 0; v < 3; ++v)
            if (Table::Slot* s = table_->find(&corner[3 * v])) s->last = index;
        return;
    }
    while (samples_.size() >= max_samples_ || !table_->reserve(3)) {
        downsample();
        if (!sampled()) {
            for (int v = 0; v < 3; ++v)
                if (Table::Slot* s = table_->find(&corner[3 * v])) s->last = index;
            return;
        }
    }
    for (int v = 0; v < 3; ++v) table_->ref(&corner[3 * v], index);
    Sample& s = samples_.emplace_back();
    s.index = index;
    std::memcpy(s.corner, corner, sizeof corner);
}

void OrderMeter::downsample() {
    ++level_;
    const uint64_t mask = (uint64_t{1} << level_) - 1;
    size_t kept = 0;
    for (const Sample& s : samples_) {
        if ((mix64(s.index) & mask) == 0) {
            samples_[kept++] = s;
        } else {
            for (int v = 0; v < 3; ++v) table_->unref(&s.corner[3 * v]);
        }
    }
    samples_.resize(kept);
}

OrderReport OrderMeter::finish() {
    OrderReport r;
    r.triangles = count_;
    r.descents = descents_;
    r.sample_rate = std::ldexp(1.0, -level_);
    // L(i) for each sample; samples are in index order, so opens come sorted.
    std::vector<uint64_t> close(samples_.size());
    for (size_t k = 0; k < samples_.size(); ++k) {
        uint64_t l = samples_[k].index;
        for (int v = 0; v < 3; ++v) l = std::max(l, table_->find(&samples_[k].corner[3 * v])->last);
        close[k] = l;
    }
    std::vector<uint64_t> closes;
    closes.reserve(close.size());
    for (size_t k = 0; k < samples_.size(); ++k)
        if (close[k] > samples_[k].index) closes.push_back(close[k]);
    std::sort(closes.begin(), closes.end());
    // Sweep: the open count only rises at an open, so its maximum is seen right after one.
    uint64_t open = 0, best = 0, best_at = 0;
    size_t c = 0;
    for (size_t k = 0; k < samples_.size(); ++k) {
        const uint64_t i = samples_[k].index;
        while (c < closes.size() && closes[c] <= i) {
            --open;
            ++c;
        }
        if (close[k] > i && ++open > best) {
            best = open;
            best_at = i;
        }
    }
    r.width = static_cast<uint64_t>(std::llround(static_cast<double>(best) / r.sample_rate));
    r.width_at = best_at;
    if (!r.exact()) r.width_error = 3 * std::sqrt(static_cast<double>(r.width) * (1 - r.sample_rate) / r.sample_rate);
    samples_ = std::vector<Sample>();  // frees it (`= {}` would keep the capacity)
    table_ = std::make_unique<Table>(1024);
    return r;
}

uint64_t buffer_needed(const OrderReport& report, double ratio) {
    const double needed = buffer_per_width(ratio) * (static_cast<double>(report.width) + report.width_error);
    return static_cast<uint64_t>(std::ceil(needed * (1 - 1e-12)));  // 2.4 × 500000 is not 1200001
}

BufferVerdict buffer_verdict(const OrderReport& report, uint64_t buffer_triangles, double ratio) {
    const double b = static_cast<double>(buffer_triangles);
    const double w = static_cast<double>(report.width);
    if (buffer_needed(report, ratio) <= buffer_triangles) return BufferVerdict::kSuffices;
    if (w - report.width_error > b) return BufferVerdict::kTooSmall;
    return BufferVerdict::kUncertain;
}

std::optional<OrderReport> measure_file_order(const std::string& path, std::string_view from,
                                              const io::ReadOptions& options) {
    if (path == "-") return std::nullopt;
    io::ReadOptions positions = options;  // the order measure looks at positions only
    positions.channels = io::ChannelKinds::none();
    io::Input in = io::open_input(path, from, positions);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity);
    OrderMeter meter(options.memory_budget_bytes);
    while (in.reader->next(chunk)) meter.add(chunk);
    return meter.finish();
}

}  // namespace meshstream::compare
