// The stream decimator: the schedule of Wu & Kobbelt 2003, §4.1 driven triangle by
// triangle, with READ (§4.2), DECIMATE (§4.3) and WRITE (§4.4) from their own files, plus
// the sorted-sweep finalization of hole boundaries and forced writes for stuck buffers.
#include "decimate/stream_decimator.hpp"

#include "decimate/attribute_store.hpp"
#include "decimate/collapse_queue.hpp"
#include "decimate/greedy.hpp"
#include "decimate/halfedge_buffer.hpp"
#include "decimate/phase_timers.hpp"
#include "decimate/random.hpp"
#include "decimate/schedule.hpp"
#include "decimate/writing.hpp"
#include "io/error.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace meshstream::decimate {
namespace {

// At the end of input, a buffer of at most this many faces whose queue holds no valid collapse
// is scanned for one (a scan rates every half-edge: about 2 ms at this size).
constexpr size_t kScanLimit = 4096;
// Candidates for a forced write.
constexpr int kForcedCandidates = 8;

// The options, checked before anything is allocated: an io::OptionError naming the setting and
// the value given (the commands check their flags first, with their own messages).
const Options& checked(const Options& options, std::optional<uint64_t> input_count) {
    using io::mention;
    using io::Setting;
    auto refuse = [](Setting setting, const std::string& why) { throw io::OptionError(setting, why); };
    if (options.target && !input_count)
        refuse(Setting::kTarget, mention(Setting::kTarget) + " needs the input's triangle count, which is not known");
    if (!options.target && !(options.ratio > 0 && options.ratio <= 1)) {
        char ratio[32];
        std::snprintf(ratio, sizeof ratio, "%g", options.ratio);
        refuse(Setting::kRatio, mention(Setting::kRatio) + " must be in (0, 1], got " + ratio);
    }
    if (options.target && *options.target > *input_count)
        refuse(Setting::kTarget, mention(Setting::kTarget) + " " + std::to_string(*options.target) +
                                     " is more than the " + std::to_string(*input_count) + " triangles of the input");
    if (options.sorted_by_minimum && !options.sorted_axis)
        refuse(Setting::kSortedAxis, "sorting by minimum needs " + mention(Setting::kSortedAxis));
    if (options.buffer_triangles < 16)
        refuse(Setting::kBuffer, mention(Setting::kBuffer) + " must hold at least 16 triangles, got " +
                                     std::to_string(options.buffer_triangles));
    if (options.sorted_axis && (*options.sorted_axis < 0 || *options.sorted_axis > 2))
        refuse(Setting::kSortedAxis,
               mention(Setting::kSortedAxis) + " must be 0, 1 or 2, got " + std::to_string(*options.sorted_axis));
    if (options.output_chunk_triangles == 0)
        refuse(Setting::kOutputChunk, mention(Setting::kOutputChunk) + " must be at least 1 triangle, got 0");
    if (options.part != Part::kWhole && options.target)
        refuse(Setting::kTarget,
               "a range or the seam pass takes " + mention(Setting::kRatio) + ", not " + mention(Setting::kTarget));
    if (options.earlier_span && (options.part != Part::kRange || !options.sorted_axis))
        refuse(Setting::kPart, "an earlier span needs a range (Part::kRange) on a sorted axis");
    return options;
}

double choose_ratio(const Options& options, std::optional<uint64_t> input_count) {
    if (!options.target) return options.ratio;
    if (*input_count == 0) return 1.0;
    return std::min(1.0, double(*options.target) / double(*input_count));
}

}  // namespace

struct StreamDecimator::Impl {
    Impl(const Options& options, io::InputCount own, const io::InputCount* input, const AttributeLayout& attributes);

    void push(const io::TriangleChunk& in, double weight, const Emit& out);
    void finish(const Emit& out);
    void finish_at(uint64_t target, const Emit& out);
    void finish_range(const Emit& interior, const Emit& first_seam, const Emit& last_seam);

    void read_triangle(const io::TriangleChunk& in, size_t i, const uint64_t hashes[3], const Emit& out);
    void make_room(const Emit& out);
    void write_one(const Emit& out, bool allow_forced);
    void sweep();
    void track_sweep(const float tri[9]);
    void follow_dropped();
    double budget() const;
    void decimate_final(size_t keep);  // down to `keep` faces in core (kRange: follows budget())
    void collect_stats();

    Options options_;
    io::InputCount own_count_;     // the count given to the first constructor
    const io::InputCount* input_;  // own_count_ or the caller's read loop's
    double ratio_;
    HalfEdgeBuffer buffer_;
    std::unique_ptr<AttributeStore> attributes_;  // null for positions only
    std::vector<double> face_scalars_;            // the triangle being read's (with attributes_)
    CollapseQueue queue_;
    Rng rng_;
    TriangleOutput output_;
    uint64_t next_id_ = 0;
    double weight_ = 1;       // input triangles each triangle being read stands for (kSeams)
    double represented_ = 0;  // input triangles the triangles read stand for (kRange, kSeams)
    Stats stats_;
    bool finished_ = false;

    // Sorted input (--sorted-axis): FIFO of vertices entering P_in with their coordinate.
    struct SweepEntry {
        float coordinate;
        uint32_t vertex, generation;
    };
    std::unique_ptr<SweepEntry[]> sweep_queue_;
    size_t sweep_capacity_ = 0, sweep_head_ = 0, sweep_size_ = 0;
    // Ascending input: the front is the largest triangle minimum read (lo_max_); descending:
    // the smallest triangle maximum (hi_min_). The direction is decided once the front has
    // left the first triangle by more than two margins.
    double lo_max_ = -INFINITY, hi_min_ = INFINITY, sweep_margin_ = 0;
    double first_lo_ = 0, first_hi_ = 0;
    bool sweep_started_ = false, sweep_enabled_ = true;
    std::optional<double> swept_to_;  // threshold of the last sweep that finalized vertices
};

// The public face: each call hands a whole chunk or the end of input to the implementation.
StreamDecimator::StreamDecimator(const Options& options, std::optional<uint64_t> input_triangle_count,
                                 const AttributeLayout& attributes)
    : impl_(std::make_unique<Impl>(options, io::InputCount{input_triangle_count}, nullptr, attributes)) {}

StreamDecimator::StreamDecimator(const Options& options, const io::InputCount& input, const AttributeLayout& attributes)
    : impl_(std::make_unique<Impl>(options, io::InputCount{input.promised}, &input, attributes)) {}

StreamDecimator::StreamDecimator(StreamDecimator&&) noexcept = default;
StreamDecimator& StreamDecimator::operator=(StreamDecimator&&) noexcept = default;
StreamDecimator::~StreamDecimator() = default;

void StreamDecimator::push(const io::TriangleChunk& in, const Emit& out) { impl_->push(in, 1.0, out); }
void StreamDecimator::push(const io::TriangleChunk& in, double weight, const Emit& out) {
    impl_->push(in, weight, out);
}
void StreamDecimator::finish(const Emit& out) { impl_->finish(out); }
void StreamDecimator::finish_at(uint64_t target, const Emit& out) { impl_->finish_at(target, out); }
void StreamDecimator::finish_range(const Emit& interior, const Emit& first_seam, const Emit& last_seam) {
    impl_->finish_range(interior, first_seam, last_seam);
}
const Stats& StreamDecimator::stats() const { return impl_->stats_; }
double StreamDecimator::ratio() const { return impl_->ratio_; }

StreamDecimator::Impl::Impl(const Options& options, io::InputCount own, const io::InputCount* input,
                            const AttributeLayout& attributes)
    : options_(checked(options, own.promised)),
      own_count_(own),
      input_(input != nullptr ? input : &own_count_),
      ratio_(choose_ratio(options, own.promised)),
      buffer_(options.buffer_triangles, options.weld_eps),
      attributes_(attributes.any() ? std::make_unique<AttributeStore>(attributes, options.buffer_triangles) : nullptr),
      queue_(options.buffer_triangles),
      rng_(options.seed),
      output_(options.output_chunk_triangles, attributes_ ? &attributes_->layout() : nullptr) {
    buffer_.set_attributes(attributes_.get());
    // The seam pass collapses along its full-resolution seams first (finish_at falls back to
    // every edge once they are done).
    if (options.part == Part::kSeams) buffer_.set_full_resolution_first(true);
    face_scalars_.resize(attributes.face_scalar_count());
    stats_.buffer_capacity = options.buffer_triangles;
    if (options.sorted_axis) {
        sweep_capacity_ = 3 * options.buffer_triangles + 3;
        if (options.sorted_by_minimum) stats_.sweep_direction = 1;
        sweep_queue_.reset(new SweepEntry[sweep_capacity_]);
    }
}

uint64_t StreamDecimator::expected_output(double ratio, uint64_t input_triangle_count) {
    return final_triangle_count(ratio, input_triangle_count);
}

size_t StreamDecimator::reserved_bytes(size_t buffer_triangles, const AttributeLayout& attributes) {
    return HalfEdgeBuffer::reserved_bytes(buffer_triangles) + CollapseQueue::reserved_bytes(buffer_triangles) +
           (attributes.any() ? AttributeStore::reserved_bytes(attributes, buffer_triangles) : 0);
}

void StreamDecimator::Impl::push(const io::TriangleChunk& in, double weight, const Emit& out) {
    if (finished_) throw std::logic_error("StreamDecimator::push after finish()");
    assert(weight == 1.0 || options_.part == Part::kSeams);
    weight_ = weight;
    const std::span<const float> xyz = in.xyz();
    // NaN/inf corners can be neither welded nor finalized (the commands drop them first).
    if (!std::all_of(xyz.begin(), xyz.end(), [](float v) { return std::isfinite(v); }))
        throw std::invalid_argument("StreamDecimator::push needs finite coordinates");
    if (attributes_ && !attributes_->layout().carried_by(in.channels()))
        throw std::invalid_argument("StreamDecimator::push needs the chunk to carry the decimator's channels");
    // Welding reads a random hash slot and then a random vertex per corner; prefetching them
    // a few triangles ahead overlaps those misses (hints only: results do not change). Each
    // corner is hashed once, kept in a small ring until the triangle is read.
    constexpr size_t kSlotsAhead = 8, kVerticesAhead = 4, kRing = 16;
    uint64_t ring[kRing][3];
    const size_t n = in.size();
    for (size_t i = 0; i < std::min(n, kSlotsAhead); ++i) {
        buffer_.weld_hashes(&xyz[9 * i], ring[i % kRing]);
        buffer_.prefetch_triangle(ring[i % kRing], 0);
    }
    for (size_t i = 0; i < n; ++i) {
        if (i + kSlotsAhead < n) {
            uint64_t* hashes = ring[(i + kSlotsAhead) % kRing];
            buffer_.weld_hashes(&xyz[9 * (i + kSlotsAhead)], hashes);
            buffer_.prefetch_triangle(hashes, 0);
        }
        if (i + kVerticesAhead < n) {
            const uint64_t* hashes = ring[(i + kVerticesAhead) % kRing];
            buffer_.prefetch_triangle(hashes, 1);
            // With channels, a welded corner also compares its values with its vertex's and adds
            // to its attribute quadric, in a record of its own pool.
            if (attributes_)
                for (int k = 0; k < 3; ++k) attributes_->prefetch(buffer_.welded_hint(hashes[k]));
            // About every other triangle brings a new vertex: the slot of the one after next.
            const uint32_t fresh = buffer_.allocation_hint(1);
            buffer_.prefetch_vertex(fresh);
            if (attributes_) attributes_->prefetch(fresh);
        }
        read_triangle(in, i, ring[i % kRing], out);
    }
}

void StreamDecimator::Impl::read_triangle(const io::TriangleChunk& in, size_t i, const uint64_t hashes[3],
                                          const Emit& out) {
    const float* tri = &in.xyz()[9 * i];
    if (buffer_.full() || buffer_.free_vertex_count() < 3) make_room(out);
    // The triangle's channels, as the attribute store keeps them.
    float corners[3 * kMaxAttributeComponents];
    uint32_t material = 0;
    double* fs = face_scalars_.data();
    if (attributes_) {
        const AttributeLayout& layout = attributes_->layout();
        const int m = layout.size();
        for (int k = 0; k < 3; ++k) layout.gather(in, i, k, corners + k * m);
        attributes_->sanitize(corners, 3 * size_t(m));
        if (const uint32_t* mat = in.material_at(i)) material = *mat;
        for (size_t c = 0; c < face_scalars_.size(); ++c) fs[c] = *in.face_scalar_at(i, c);
    }
    if (options_.sorted_axis) track_sweep(tri);
    const HalfEdgeBuffer::Added added = [&] {
        const PhaseTimer timer(Phase::kRead);
        return buffer_.add_triangle(tri, hashes);
    }();
    ++stats_.triangles_in;
    represented_ += weight_;
    if (added.face == kNoIndex) {
        // A triangle the weld grid collapsed is gone, as the weld asked (passed through it took
        // output budget, and whole-mesh writers dropped it after the count was printed); one
        // that came with repeated corners passes through as it came.
        auto same = [&](int a, int b) {
            return tri[3 * a] == tri[3 * b] && tri[3 * a + 1] == tri[3 * b + 1] && tri[3 * a + 2] == tri[3 * b + 2];
        };
        if (!same(0, 1) && !same(1, 2) && !same(2, 0)) {
            ++stats_.weld_dropped;
            return;
        }
        if (attributes_) {
            const int m = attributes_->size();
            const PassedChannels passed{{corners, corners + m, corners + 2 * m}, material, fs};
            pass_through(buffer_, added.vertex, next_id_, output_, out, &passed);
        } else {
            pass_through(buffer_, added.vertex, next_id_, output_, out);
        }
        ++stats_.degenerate_passed;
        return;
    }
    if (attributes_) attributes_->add_face(buffer_, added.face, corners, material, fs);
    // The seam pass: a vertex made by a seam piece's triangle (standing for itself) is at full
    // resolution until a triangle of a decimated interior (standing for more) reaches it.
    if (options_.part == Part::kSeams)
        for (const uint32_t v : added.vertex) {
            Vertex& x = buffer_.vertex(v);
            if (weight_ > 1)
                x.flags &= ~kFullResolution;
            else if (x.face_count == 1)
                x.flags |= kFullResolution;
        }
    // A vertex whose fan this triangle closed left P_in: its edges are rated now, while the fan
    // is in the cache, not when the buffer is next full. (The seam pass rates only when a
    // collapse is due: make_room.)
    if (options_.part != Part::kSeams && buffer_.has_pending()) rate_pending(buffer_, queue_);
    stats_.peak_buffer_triangles = std::max(stats_.peak_buffer_triangles, buffer_.face_count());
    if (options_.sorted_axis) {
        // New P_in vertices join the sweep queue in reading order, which on sorted input is
        // (nearly) coordinate order.
        for (uint32_t v : added.vertex) {
            const Vertex& x = buffer_.vertex(v);
            if (x.face_count != 1 || (x.flags & kInHash) == 0) continue;
            if (sweep_size_ == sweep_capacity_) {  // full: drop the oldest entry
                sweep_head_ = (sweep_head_ + 1) % sweep_capacity_;
                --sweep_size_;
            }
            sweep_queue_[(sweep_head_ + sweep_size_++) % sweep_capacity_] =
                SweepEntry{x.pos[*options_.sorted_axis], v, x.generation};
        }
    }
}

void StreamDecimator::Impl::track_sweep(const float tri[9]) {
    const int axis = *options_.sorted_axis;
    const double lo = std::min({tri[axis], tri[3 + axis], tri[6 + axis]});
    const double hi = std::max({tri[axis], tri[3 + axis], tri[6 + axis]});
    // A triangle reaching into the region already swept may weld to a vertex finalized too
    // early (a crack): the input is not sorted as stated. Count it and stop sweeping. Sorted
    // by minimum, any descent of the minimum is one, swept or not.
    const bool behind_front = options_.sorted_by_minimum && lo < lo_max_;
    if (behind_front || (swept_to_ && (stats_.sweep_direction > 0 ? lo < *swept_to_ : hi > *swept_to_))) {
        ++stats_.sort_violations;
        sweep_enabled_ = false;
    }
    if (!sweep_started_) {
        first_lo_ = lo;
        first_hi_ = hi;
        sweep_started_ = true;
    }
    // Sorted by minimum, no triangle to come reaches behind the front: the margin is only the
    // weld grid's (a corner snaps by up to half a cell), and a long triangle cannot hold the
    // sweep off.
    sweep_margin_ = options_.sorted_by_minimum ? options_.weld_eps : std::max(sweep_margin_, hi - lo);
    lo_max_ = std::max(lo_max_, lo);
    hi_min_ = std::min(hi_min_, hi);
    if (stats_.sweep_direction == 0) {
        if (lo_max_ - first_hi_ > 2 * sweep_margin_)
            stats_.sweep_direction = 1;
        else if (first_lo_ - hi_min_ > 2 * sweep_margin_)
            stats_.sweep_direction = -1;
    }
}

void StreamDecimator::Impl::sweep() {
    // A future triangle has a sort key ≥ the front (every key lies within its triangle, and
    // the front is the largest triangle minimum read so far), so it can only reach vertices
    // within one triangle extent behind the front. Twice the largest extent seen leaves room
    // for somewhat larger triangles to come (sorted by minimum, no vertex to come lies behind
    // the front: only the weld grid's cell is kept). Vertices further behind that are still
    // open are true boundary (holes): finalizing them lets their triangles be decimated and
    // written.
    // Descending input is the mirror image (front = smallest triangle maximum).
    const int direction = stats_.sweep_direction;
    if (!sweep_enabled_ || direction == 0) return;
    const double threshold = direction > 0 ? lo_max_ - 2 * sweep_margin_ : hi_min_ + 2 * sweep_margin_;
    const double ahead = direction > 0 ? lo_max_ + 2 * sweep_margin_ : hi_min_ - 2 * sweep_margin_;
    size_t requeued = 0;
    while (sweep_size_ > 0) {
        const SweepEntry e = sweep_queue_[sweep_head_];
        const bool behind = direction > 0 ? double(e.coordinate) < threshold : double(e.coordinate) > threshold;
        if (!behind) {
            // A corner far ahead of the front (a long triangle's far end, read early) would
            // hold up the queue behind it: it goes to the back, once per sweep at most.
            const bool far = direction > 0 ? double(e.coordinate) > ahead : double(e.coordinate) < ahead;
            if (!far || requeued == sweep_size_) break;
            ++requeued;
            sweep_head_ = (sweep_head_ + 1) % sweep_capacity_;
            sweep_queue_[(sweep_head_ + sweep_size_ - 1) % sweep_capacity_] = e;
            continue;
        }
        const Vertex& x = buffer_.vertex(e.vertex);
        // A range's vertex that an earlier range's triangle may reach stays open: it may be on a
        // seam (the seam pass joins it); being behind the front, it never comes up again.
        const bool shared = options_.earlier_span && double(e.coordinate) >= (*options_.earlier_span)[0] &&
                            double(e.coordinate) <= (*options_.earlier_span)[1];
        if (!shared && (x.flags & (kAlive | kInHash)) == (kAlive | kInHash) && x.generation == e.generation) {
            buffer_.finalize_vertex(e.vertex);
            ++stats_.vertices_finalized_by_sweep;
            swept_to_ = threshold;
        }
        sweep_head_ = (sweep_head_ + 1) % sweep_capacity_;
        --sweep_size_;
    }
}

void StreamDecimator::Impl::write_one(const Emit& out, bool allow_forced) {
    const PhaseTimer timer(Phase::kWrite);
    uint32_t f = pick_write(buffer_);
    if (f == kNoIndex) {
        // Every in-core triangle touches P_in: the input is not in a streaming-friendly order
        // (or holes pile up). Write one anyway rather than fail.
        assert(allow_forced);
        (void)allow_forced;
        // Of a few random faces, the one with the most written corners, then the fewest on
        // P_in: P_out grows as one front instead of scattering, which would leave written
        // vertices everywhere (they never collapse) and stall the next rounds as well.
        // Random slots; the buffer is full or nearly so when writes are forced, so nearly every
        // draw finds a face (a bounded number of draws, then the first face there is).
        int best_score = -1;
        for (int draws = 0, found = 0; found < kForcedCandidates && draws < 8 * kForcedCandidates; ++draws) {
            const uint32_t g = rng_.below(buffer_.face_slots());
            if (!buffer_.face_alive(g)) continue;
            ++found;
            int score = 0;
            for (uint32_t k = 0; k < 3; ++k) {
                const uint8_t flags = buffer_.vertex(buffer_.corner_vertex(half_edge(g, k))).flags;
                score += (flags & kFrozen) ? 4 : (flags & kInHash) ? 0 : 1;
            }
            if (score > best_score) {
                best_score = score;
                f = g;
            }
        }
        for (uint32_t g = 0; f == kNoIndex; ++g)
            if (buffer_.face_alive(g)) f = g;
        ++stats_.forced_writes;
    }
    stats_.vertices_moved += write_face(buffer_, f, next_id_, output_, out);
}

void StreamDecimator::Impl::follow_dropped() {
    if (!options_.target || input_->dropped == 0 || *input_->promised == 0) return;
    // The most the input can still hold: never below the triangles already read, so the
    // writes this ratio allows never pass the target.
    const uint64_t usable = *input_->usable();
    ratio_ = usable > 0 ? std::min(1.0, double(*options_.target) / double(usable)) : 1.0;
}

double StreamDecimator::Impl::budget() const {
    if (options_.part == Part::kWhole) return resolution_budget(ratio_, stats_.triangles_in, output_.triangle_count());
    return part_budget(ratio_, represented_, output_.triangle_count(), buffer_.pinned_face_count());
}

void StreamDecimator::Impl::make_room(const Emit& out) {
    follow_dropped();
    if (options_.sorted_axis) sweep();
    const RoomPlan plan = plan_full_buffer(buffer_.face_capacity(), budget());
    // The seam pass has nothing to decimate where the ranges' output is at the ratio already: its
    // edges are rated only when a collapse is due (each vertex stays listed until then).
    if (options_.part != Part::kSeams || buffer_.face_count() > plan.decimate_to) rate_pending(buffer_, queue_);
    if (options_.part == Part::kWhole) {
        while (buffer_.face_count() > plan.decimate_to && collapse_cheapest(buffer_, queue_)) ++stats_.collapses;
    } else {
        // A collapse may remove faces on P_in, which stood for themselves: the budget falls
        // with them, and is followed as it falls.
        while (buffer_.face_count() > plan_full_buffer(buffer_.face_capacity(), budget()).decimate_to &&
               collapse_cheapest(buffer_, queue_))
            ++stats_.collapses;
    }
    while (buffer_.face_count() > plan.write_to) {
        // Early when above the level planned, the budget rounded up (each write lowers both).
        if (double(buffer_.face_count()) > std::ceil(budget())) ++stats_.premature_writes;
        write_one(out, true);
    }
    if (buffer_.free_vertex_count() < 3) stats_.orphans_evicted += buffer_.evict_orphans();
    assert(!buffer_.full() && buffer_.free_vertex_count() >= 3);
}

void StreamDecimator::Impl::finish(const Emit& out) {
    if (finished_) throw std::logic_error("StreamDecimator::finish called twice");
    finish_at(options_.target ? *options_.target : final_triangle_count(ratio_, stats_.triangles_in), out);
}

void StreamDecimator::Impl::finish_at(uint64_t target, const Emit& out) {
    if (finished_) throw std::logic_error("StreamDecimator::finish called twice");
    if (options_.part == Part::kRange) throw std::logic_error("StreamDecimator: a range ends with finish_range()");
    finished_ = true;
    // The seam pass: a vertex still open at the end is on a hole's rim, not on a seam (a seam's
    // vertices closed when the next range's seam piece came); its collapses take their turn in
    // the greedy order with the rest, as one thread's rims do.
    if (options_.part == Part::kSeams)
        for (uint32_t v = 0; v < buffer_.vertex_slots(); ++v) {
            Vertex& x = buffer_.vertex(v);
            if ((x.flags & (kAlive | kInHash)) == (kAlive | kInHash)) x.flags &= ~kFullResolution;
        }
    // No more input: whatever is still open is true boundary.
    buffer_.finalize_all();
    stats_.target_triangles = target;
    const size_t budget = final_budget(target, output_.triangle_count());
    decimate_final(budget);
    // Collapses remove two faces; an odd remainder needs one boundary collapse.
    if (buffer_.face_count() == budget + 1 && collapse_one_boundary_edge(buffer_)) ++stats_.collapses;
    while (buffer_.face_count() > 0) write_one(out, false);
    output_.flush(out);
    collect_stats();
}

void StreamDecimator::Impl::finish_range(const Emit& interior, const Emit& first_seam, const Emit& last_seam) {
    if (finished_) throw std::logic_error("StreamDecimator::finish_range called twice");
    if (options_.part != Part::kRange) throw std::logic_error("StreamDecimator::finish_range needs Part::kRange");
    finished_ = true;
    // Nothing is finalized: a vertex still open may be shared with another range. The faces on
    // P_in stand for themselves (budget()), the rest come down to the ratio.
    decimate_final(0);
    stats_.target_triangles = output_.triangle_count() + buffer_.face_count();
    for (uint32_t f = pick_write(buffer_); f != kNoIndex; f = pick_write(buffer_))
        stats_.vertices_moved += write_face(buffer_, f, next_id_, output_, interior);
    output_.flush(interior);
    // The faces on P_in, in slot order; their P_in corners are frozen where they were read.
    const uint32_t half = buffer_.faces_added() / 2;
    for (const bool first : {true, false}) {
        const Emit& seam = first ? first_seam : last_seam;
        for (uint32_t f = 0; f < buffer_.face_slots(); ++f)
            if (buffer_.face_alive(f) && (buffer_.face(f).born <= half) == first)
                stats_.vertices_moved += write_face(buffer_, f, next_id_, output_, seam);
        output_.flush(seam);
    }
    collect_stats();
}

void StreamDecimator::Impl::decimate_final(size_t keep) {
    // A range's budget falls as collapses remove faces on P_in (they stood for themselves): it is
    // followed as it falls. It ends with each vertex on P_in standing for one of their faces
    // (range_end_budget).
    const bool range = options_.part == Part::kRange;
    auto in_core = [&] {
        if (!range) return keep;
        const double b = range_end_budget(ratio_, represented_, output_.triangle_count(), buffer_.pinned_face_count(),
                                          buffer_.open_vertex_count());
        return size_t(std::max(0.0, std::round(b)));
    };
    rate_pending(buffer_, queue_);
    bool rated_all = false;
    while (buffer_.face_count() >= in_core() + 2) {
        if (collapse_cheapest(buffer_, queue_)) {
            ++stats_.collapses;
        } else if (buffer_.full_resolution_first()) {
            // The seam pass's seams have no valid collapse left: the rest of the target from
            // every edge, cheapest first.
            buffer_.set_full_resolution_first(false);
            rate_all(buffer_, queue_);
            rated_all = true;
        } else if (!rated_all) {
            // The queue ran out of valid collapses: every edge rated afresh, refused ones too
            // (a refusal may have lapsed without a neighbour of its ends changing).
            rate_all(buffer_, queue_);
            rated_all = true;
        } else if (buffer_.face_count() <= kScanLimit && collapse_best_of_all(buffer_)) {
            // A small buffer is scanned for the few valid collapses left, or shows there are
            // none (a closed 5 558 triangle elephant at 1 %).
            ++stats_.collapses;
            rated_all = false;
        } else {
            stats_.no_valid_collapse_left = buffer_.face_count() <= kScanLimit;
            break;
        }
    }
}

void StreamDecimator::Impl::collect_stats() {
    stats_.triangles_out = output_.triangle_count();
    stats_.peak_vertices = buffer_.peak_vertices();
    stats_.vertices_merged = buffer_.vertices_merged();
    stats_.nonmanifold_edges = buffer_.nonmanifold_edges();
    stats_.boundary_edges = buffer_.boundary_edges();
    if (attributes_) {
        stats_.seam_vertices = attributes_->seam_vertices();
        stats_.attribute_values_zeroed = attributes_->non_finite_values();
    }
}

}  // namespace meshstream::decimate
