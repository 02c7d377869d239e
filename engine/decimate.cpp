// One call per decimation job: see decimate.hpp.
#include "engine/decimate.hpp"

#include "engine/files.hpp"
#include "engine/units.hpp"
#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/triangle_records.hpp"
#include "io/triangle_stream.hpp"
#include "sort/external_sort.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>

namespace meshstream::engine {
namespace {

using io::mention;
using io::Setting;

// The shortest text that reads back as `v`.
std::string number_text(double v) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
    return ec == std::errc() ? std::string(text, end) : std::string("?");
}

std::string shown_input(const std::string& path) { return path == "-" ? std::string("<stdin>") : path; }

// The read loop decimate reads through: the file as settings say, its bad triangles dropped (the
// decimator cannot use them), or refused with strict reading.
io::TriangleInput open_decimate_input(const DecimateSettings& s, const io::ReadOptions& options) {
    return io::TriangleInput(io::open_input(s.input, s.input_format, options),
                             s.read.strict ? io::BadTriangles::kRefuse : io::BadTriangles::kDrop);
}

// The weld's grid step: absolute, or a percentage of the bounding-box diagonal, found by a first
// pass over the input (a regular file only: a stream cannot be read twice).
double weld_epsilon(const DecimateSettings& s, const std::string& input_name, ProgressSink& progress) {
    if (!(s.weld.size >= 0) || !std::isfinite(s.weld.size))
        throw io::OptionError(Setting::kWeld, "the weld must be a non-negative size");
    if (!s.weld.of_diagonal) return s.weld.size;
    if (!is_regular_file(s.input))
        throw io::OptionError(Setting::kWeld, input_name + ": " + mention(Setting::kWeld) + " " +
                                                  number_text(s.weld.size) +
                                                  "% needs the bounding box, found in a first pass over the "
                                                  "input, which a stream cannot be read twice for; give an absolute "
                                                  "size instead");
    const io::Bounds box = input_bounds(s.input, s.input_format, s.read, progress);
    double diag2 = 0;
    for (int i = 0; i < 3; ++i) {
        const double d = double(box.max[i]) - box.min[i];
        diag2 += d * d;
    }
    return std::isfinite(diag2) ? s.weld.size / 100 * std::sqrt(diag2) : 0;  // no finite corner: nothing to weld
}

// What the decimator carries from input to output: the channels read that the output format
// keeps, as an attribute layout; and what is dropped for the output's sake.
struct Carried {
    io::Channels channels;  // what the reader fills and the writer gets (no vertex ids)
    decimate::AttributeLayout layout;
    std::string dropped;  // in words; empty when nothing is
    // Vertex scalars whose type float cannot hold exactly (the decimator keeps a corner's values
    // as float), in words; empty when none.
    std::string rounded;
};

Carried carried_channels(const DecimateSettings& s, const io::MeshHeader& header, const io::Format& out_format,
                         const io::WriteOptions& wo, const std::string& input_name) {
    Carried c;
    // What the kinds asked for leave (the reader may read less: nothing, for an output that
    // keeps nothing).
    io::Channels wanted = s.read.channels.of(header.channels);
    wanted.vertex_id = false;
    c.channels = io::writable_channels(out_format, wanted, wo);
    c.channels.vertex_id = false;
    c.dropped = io::describe_missing(wanted, c.channels);
    try {
        c.layout = decimate::AttributeLayout(c.channels, s.weights);
    } catch (const io::OptionError& e) {
        throw io::OptionError(Setting::kWeights, input_name + ": " + mention(Setting::kWeights) + ": " + e.raw_what());
    }
    if (c.layout.size() > decimate::kMaxAttributeComponents)
        throw io::OptionError(Setting::kDrop, input_name + ": " + std::to_string(c.layout.size()) +
                                                  " normal, colour, texture and scalar values per corner, more than "
                                                  "the " +
                                                  std::to_string(decimate::kMaxAttributeComponents) +
                                                  " decimate carries: leave some out with " + mention(Setting::kDrop) +
                                                  " extra (or uvs)");
    for (const io::ScalarChannel& sc : c.channels.vertex_scalars)
        if (sc.type == io::ScalarType::kFloat64 || sc.type == io::ScalarType::kInt32 ||
            sc.type == io::ScalarType::kUInt32)
            c.rounded += (c.rounded.empty() ? "'" : ", '") + sc.name + "' (" + io::scalar_type_name(sc.type) + ")";
    return c;
}

// What a decimation pass reads: fills a chunk, false at the end.
using ChunkSource = std::function<bool(io::TriangleChunk&)>;

// Every triangle read from an input that can be read once only (stdin, a pipe), spooled to a
// temporary file so that it can still be sorted: its records (io::TriangleRecords: 36 bytes a
// triangle plus the channels carried), with the bounding box of its finite coordinates. The file
// is made on the first add(); a file that cannot be made or written stops the spool (ok() false,
// error() says why) instead of failing the job, which then decimates the input as it comes.
class InputSpool {
public:
    InputSpool(std::string tmpdir, const io::Channels& channels) : tmpdir_(std::move(tmpdir)), records_(channels) {
        box_.min.fill(std::numeric_limits<float>::infinity());
        box_.max.fill(-std::numeric_limits<float>::infinity());
    }
    void add(const io::TriangleChunk& chunk) {
        if (!error_.empty()) return;
        try {
            if (!file_) file_ = std::make_unique<io::TempFile>(tmpdir_, "meshstream-spool");
            bytes_.clear();
            records_.encode(chunk, bytes_);
            file_->write(bytes_.data(), bytes_.size());
        } catch (const io::Error& e) {
            error_ = e.raw_what();
            file_.reset();
            return;
        }
        const auto xyz = chunk.xyz();
        for (size_t i = 0; i < xyz.size(); i += 3)
            for (int a = 0; a < 3; ++a)
                if (std::isfinite(xyz[i + a])) {
                    box_.min[a] = std::min(box_.min[a], xyz[i + a]);
                    box_.max[a] = std::max(box_.max[a], xyz[i + a]);
                }
        triangles_ += chunk.size();
    }
    bool ok() const { return error_.empty(); }
    const std::string& error() const { return error_; }
    const io::Bounds& bounds() const { return box_; }
    uint64_t bytes() const { return triangles_ * records_.bytes(); }
    // Reads the spool back in order, a chunk (with the spool's channels) at a time; false at the
    // end.
    bool next(io::TriangleChunk& chunk) {
        const uint64_t n = std::min<uint64_t>(chunk.capacity(), triangles_ - read_);
        if (n == 0) {
            chunk.clear();
            return false;
        }
        bytes_.resize(size_t(n) * records_.bytes());
        file_->read_at(read_ * records_.bytes(), bytes_.data(), bytes_.size());
        records_.decode(bytes_.data(), size_t(n), chunk);
        read_ += n;
        return true;
    }

private:
    std::string tmpdir_;
    io::TriangleRecords records_;
    std::vector<char> bytes_;
    std::unique_ptr<io::TempFile> file_;
    std::string error_;
    io::Bounds box_;
    uint64_t triangles_ = 0, read_ = 0;
};

// Where the decimator's output goes while the job may still start over on sorted input. A file
// output is written as it comes (a restart drops its temporary file); an output written in place
// (stdout, a pipe) is held in memory up to `hold_triangles`, then written out: from there on
// nothing can be taken back (released()).
class HeldOutput {
public:
    HeldOutput(io::Output& out, uint64_t hold_triangles) : out_(&out), limit_(hold_triangles) {}
    void write(const io::TriangleChunk& chunk) {
        if (!holding()) return out_->write(chunk);
        held_.push_back(chunk);
        held_triangles_ += chunk.size();
        if (held_triangles_ > limit_) release();
    }
    bool holding() const { return limit_ > 0 && !released_; }
    bool released() const { return released_; }
    uint64_t held_triangles() const { return held_triangles_; }
    // Writes what is held, and everything from now on.
    void release() {
        if (released_ || limit_ == 0) return;
        released_ = true;
        for (const io::TriangleChunk& c : held_) out_->write(c);
        held_.clear();
    }
    // Forgets what is held (the attempt it came from was dropped).
    void discard() {
        held_.clear();
        held_triangles_ = 0;
    }
    void rebind(io::Output& out) { out_ = &out; }

private:
    io::Output* out_;
    uint64_t limit_;
    std::vector<io::TriangleChunk> held_;
    uint64_t held_triangles_ = 0;
    bool released_ = false;
};

// The decimator's options from the settings and the input's header. `input_count` is the
// header's triangle count, or the one a first pass counted. Settings that cannot work with this
// input are io::OptionErrors.
decimate::Options decimation_options(const DecimateSettings& s, const io::MeshHeader& header, const std::string& name,
                                     std::string_view format, std::optional<uint64_t> input_count,
                                     ProgressSink& progress) {
    decimate::Options options;
    if (s.target) {
        if (!input_count)
            throw io::OptionError(Setting::kTarget,
                                  name + ": " + mention(Setting::kTarget) + " needs the input triangle count, which " +
                                      std::string(format) +
                                      " does not state up front (binary STL, Draco and glTF do), and a stream cannot "
                                      "be read twice to count it: give the input as a file, or use " +
                                      mention(Setting::kRatio));
        if (*s.target > *input_count)
            throw io::OptionError(Setting::kTarget, name + ": " + mention(Setting::kTarget) + " " +
                                                        std::to_string(*s.target) + " is more than the " +
                                                        std::to_string(*input_count) +
                                                        " triangles of the input (decimation only removes triangles)");
        options.target = *s.target;
    } else {
        options.ratio = s.ratio.value_or(0.1);
    }
    options.buffer_triangles = s.buffer;
    options.seed = s.seed;
    options.weld_eps = weld_epsilon(s, name, progress);
    options.sorted_axis = s.sorted_axis ? s.sorted_axis : header.sorted_axis;
    // The file's flag comes from `meshstream sort` (or a convert that kept its order): ascending
    // by triangle minimum. An axis of the caller's own says less: the key is not known.
    options.sorted_by_minimum = header.sorted_axis && options.sorted_axis == header.sorted_axis;
    return options;
}

// A target or ranges for a file whose header states no triangle count (OBJ, ASCII STL, PLY,
// whose faces may be polygons): the triangles decimate can use, counted in a first pass with the
// same read loop (positions only), handed to the decimator as promised with none dropped; and
// what the pass cost.
struct CountPass {
    io::InputCount count;
    double seconds = 0;
    bool for_threads = false;  // made to cut the input into ranges (else for the target)
};

CountPass count_usable_triangles(const DecimateSettings& s, const io::ReadOptions& read, ProgressSink& progress) {
    const auto start = std::chrono::steady_clock::now();
    io::TriangleInput in = open_decimate_input(s, read);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, io::Channels{});
    progress.phase("counting triangles", std::nullopt);
    while (in.next(chunk)) {
        progress.update(in.count().read, in.source().stored_offset(), in.source().stored_size());
        throw_if_cancelled(progress);
    }
    CountPass pass;
    pass.count.promised = in.count().passed();
    pass.seconds = seconds_since(start);
    return pass;
}

std::unique_ptr<decimate::StreamDecimator> make_decimator(const decimate::Options& options, const io::InputCount& count,
                                                          const decimate::AttributeLayout& attributes = {}) {
    try {  // on the heap only to catch a refused reservation here
        return std::make_unique<decimate::StreamDecimator>(options, count, attributes);
    } catch (const std::bad_alloc&) {
        // Per triangle: about 580 bytes for positions, more with the channels carried.
        const size_t bytes = decimate::StreamDecimator::reserved_bytes(options.buffer_triangles, attributes);
        // Not a setting that cannot work but memory this system will not give: the failure of
        // the run (meshstream::Error), naming the buffer that asked for it.
        throw meshstream::Error(
            mention(Setting::kBuffer) + " " + std::to_string(options.buffer_triangles) + " reserves " +
            human_bytes(double(bytes)) + " of memory (about " +
            std::to_string(bytes / std::max<size_t>(options.buffer_triangles, 1)) +
            " bytes a triangle), which this system refused: give a smaller " + mention(Setting::kBuffer) +
            " (the default " + std::to_string(decimate::kDefaultBufferTriangles) + " reserves " +
            human_bytes(
                double(decimate::StreamDecimator::reserved_bytes(decimate::kDefaultBufferTriangles, attributes))) +
            ")");
    }
}

// Pushes what `next` gives through `decimator`, updating `show_progress` after each chunk;
// returns false when `stop`, asked after each chunk, said to stop, true at the end of the input.
bool decimate_pass(const ChunkSource& next, const io::Channels& channels, decimate::StreamDecimator& decimator,
                   const decimate::Emit& emit, const std::function<void()>& show_progress,
                   const std::function<bool()>& stop, const ProgressSink& progress) {
    // The chunk carries what the decimator does: the reader fills no more.
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (next(chunk)) {
        decimator.push(chunk, emit);
        show_progress();
        throw_if_cancelled(progress);
        if (stop && stop()) return false;
    }
    return true;
}

// The input, sorted: the sorter to read it from, what reading it counted, and what it cost.
struct SortedInput {
    std::unique_ptr<sort::ExternalSorter> sorter;
    int axis = 0;
    io::InputCount count;
    DroppedTriangles dropped;
    io::MeshHeader end_header;  // the reader's header at the end (its notes)
    uint64_t temp_bytes = 0;    // peak temporary disk of the sort
};

std::unique_ptr<sort::ExternalSorter> make_sorter(int axis, uint64_t budget, const std::string& tmpdir,
                                                  ProgressSink& progress, const io::Channels& channels = {}) {
    sort::SorterOptions so;
    so.axis = axis;
    so.channels = channels;
    so.memory_budget_bytes = budget;
    so.tmpdir = tmpdir;
    so.on_merge_progress = [&progress](int pass, int pass_count, uint64_t merged) {
        progress.phase("sorting: merge pass " + std::to_string(pass) + "/" + std::to_string(pass_count), std::nullopt);
        progress.update(merged);
    };
    return std::make_unique<sort::ExternalSorter>(so);
}

// Sorts a file input: its bounding box first (the longest axis), then its triangles, read
// again through the read loop.
SortedInput sort_file(const DecimateSettings& s, uint64_t sort_budget, const io::ReadOptions& ro,
                      ProgressSink& progress, const io::Channels& channels) {
    SortedInput sorted;
    sorted.axis = longest_axis(input_bounds(s.input, s.input_format, ro, progress));
    io::TriangleInput in = open_decimate_input(s, ro);
    sorted.sorter = make_sorter(sorted.axis, sort_budget, s.read.tmpdir, progress, channels);
    progress.phase("sorting: reading", in.header().triangle_count);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (in.next(chunk)) {
        sorted.sorter->add(chunk);
        progress.update(in.count().read, in.source().stored_offset(), in.source().stored_size());
        throw_if_cancelled(progress);
    }
    sorted.count = in.count();
    sorted.dropped = dropped_triangles(in);
    sorted.end_header = in.header();
    in.close();
    sorted.sorter->finish_input();
    sorted.temp_bytes = sorted.sorter->stats().peak_temp_bytes;
    return sorted;
}

// Sorts an input read once: the rest of it goes to the spool, which is then sorted.
SortedInput sort_spooled(io::TriangleInput& in, InputSpool& spool, uint64_t sort_budget, const std::string& tmpdir,
                         ProgressSink& progress, const io::Channels& channels) {
    progress.phase("spooling the input", in.header().triangle_count);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (in.next(chunk)) {
        spool.add(chunk);
        progress.update(in.count().read, in.source().stored_offset(), in.source().stored_size());
        throw_if_cancelled(progress);
    }
    if (!spool.ok()) throw io::Error(in.name(), "cannot spool the input to sort it: " + spool.error());
    SortedInput sorted;
    sorted.count = in.count();
    sorted.dropped = dropped_triangles(in);
    sorted.end_header = in.header();
    sorted.axis = longest_axis(spool.bounds());
    sorted.sorter = make_sorter(sorted.axis, sort_budget, tmpdir, progress, channels);
    progress.phase("sorting: reading the spool", sorted.count.passed());
    uint64_t done = 0;
    while (spool.next(chunk)) {
        sorted.sorter->add(chunk);
        progress.update(done += chunk.size());
        throw_if_cancelled(progress);
    }
    sorted.sorter->finish_input();
    sorted.temp_bytes = spool.bytes() + sorted.sorter->stats().peak_temp_bytes;
    return sorted;
}

// The read options decimate reads through: the channel kinds asked for, when the output format
// can keep any (decimate carries them); else none, so that the reader stores no attribute (a
// coloured PLY decimated to STL costs what a plain one does), while the header still lists what
// is dropped.
io::ReadOptions decimate_read_options(const DecimateSettings& s, const io::Format& out_format,
                                      const io::WriteOptions& wo) {
    io::ReadOptions read = s.read;
    io::Channels every;
    every.normal = true;
    every.color = io::ColorFormat{io::ScalarType::kFloat32, true};
    every.uv_sets = 1;
    every.vertex_scalars = {io::ScalarChannel{"s"}};
    every.material = true;
    every.face_scalars = {io::ScalarChannel{"f"}};
    if (!io::writable_channels(out_format, every, wo).has_attributes()) read.channels = io::ChannelKinds::none();
    return read;
}

// The ranges of `ranges` of an input of `cut_triangles` triangles (threads, MPI, parts): every
// job that decimates a range of the input plans it here, so that their plans agree.
RangesJob ranges_job(const DecimateSettings& s, const io::ReadOptions& read, const Carried& carried,
                     const decimate::Options& options, uint64_t cut_triangles, unsigned ranges) {
    RangesJob job;
    job.open = [&s, &read] { return open_decimate_input(s, read); };
    job.make_decimator = [&carried](const decimate::Options& o) {
        static const io::InputCount kNoCount;  // a range and the seam pass take a ratio
        return make_decimator(o, kNoCount, carried.layout);
    };
    job.tmpdir = s.read.tmpdir;
    job.channels = carried.channels;
    job.options = options;
    job.options.target.reset();
    if (options.target) job.options.ratio = std::min(1.0, double(*options.target) / double(cut_triangles));
    job.target = options.target;
    job.cut_triangles = cut_triangles;
    job.ranges = ranges;
    return job;
}

// What a part file records of the plan, for the merge to check (part_files.hpp).
PartPlan part_plan(const RangesJob& job, const Carried& carried) {
    PartPlan plan;
    plan.options = job.options;
    plan.target = job.target;
    plan.cut_triangles = job.cut_triangles;
    plan.ranges = job.ranges;
    plan.omega = carried.layout.omega();
    plan.channels = carried.channels;
    return plan;
}

std::string part_text(PartIndex part) { return std::to_string(part.k) + "/" + std::to_string(part.parts); }

// A part job: the input must be cut into exactly K ranges, as K threads would cut it.
void refuse_other_range_count(const DecimateSettings& s, PartIndex part, const std::string& input_name,
                              uint64_t cut_triangles, unsigned ranges) {
    if (ranges == part.parts) return;
    if (s.buffer < kMinRangeBuffer)
        throw io::OptionError(Setting::kPart, mention(Setting::kPart) + " " + part_text(part) + ": a " +
                                                  mention(Setting::kBuffer) + " below " +
                                                  std::to_string(kMinRangeBuffer) + " is never cut into ranges (" +
                                                  mention(Setting::kBuffer) + " " + std::to_string(s.buffer) + ")");
    throw io::OptionError(Setting::kPart,
                          input_name + ": " + std::to_string(cut_triangles) + " triangles through " +
                              mention(Setting::kBuffer) + " " + std::to_string(s.buffer) + " make at most " +
                              std::to_string(ranges) + (ranges == 1 ? " range" : " ranges") + " (each holds at least " +
                              mention(Setting::kBuffer) + " triangles), not " + std::to_string(part.parts) + ": " +
                              (ranges >= 2 ? "use " + mention(Setting::kPart) + " k/" + std::to_string(ranges) +
                                                 " or a smaller " + mention(Setting::kBuffer)
                                           : std::string("the input is too small to cut; decimate it in one job")));
}

// The settings a part job or a merge cannot work with, refused before any work.
void check_part_settings(const DecimateSettings& s) {
    const PartIndex part = *s.part;
    if (part.parts < 2 || part.parts > 1024 || part.k < 1 || part.k > part.parts)
        throw io::OptionError(Setting::kPart, mention(Setting::kPart) +
                                                  " must be k/K with 1 <= k <= K and 2 <= K <= "
                                                  "1024, found " +
                                                  part_text(part));
    const std::string both = mention(Setting::kPart) + " " + part_text(part);
    if (s.threads > 1)
        throw io::OptionError(Setting::kThreads, both + " decimates one range of the input in this job; " +
                                                     mention(Setting::kThreads) + " does not go with it");
    // Every job opens the input by its name and reads it from its start to its range.
    if (!is_regular_file(s.input))
        throw io::OptionError(Setting::kPart, shown_input(s.input) + ": " + both + ": every job reads " +
                                                  mention(Setting::kInput) + " from its start, so " +
                                                  mention(Setting::kInput) + " must be a file, not '-' or a pipe");
    if (s.sort == SortPolicy::kAlways)
        throw io::OptionError(Setting::kSort, both + ": " + mention(Setting::kSort) + " always" +
                                                  " decimates a sorted stream in one job; sort first (meshstream sort "
                                                  "IN SORTED.stl), then make the parts from the sorted file");
    if (!part.merge()) {
        if (!s.merge.empty())
            throw io::OptionError(Setting::kMerge, mention(Setting::kMerge) + " goes with the merge job, " +
                                                       mention(Setting::kPart) + " " +
                                                       part_text({part.parts, part.parts}) + ", not " + both);
        return;
    }
    if (s.merge.size() != part.parts - 1)
        throw io::OptionError(Setting::kMerge, both + " merges parts 1/" + std::to_string(part.parts) + " to " +
                                                   part_text({part.parts - 1, part.parts}) + ": give " +
                                                   mention(Setting::kMerge) + " once for each of their " +
                                                   std::to_string(part.parts - 1) + " part files, found " +
                                                   std::to_string(s.merge.size()));
}

// MPI, process 0: the other processes wait for the plan, so they are told once, whatever
// happens: the plan, or (when this ends without one, a failure included) that there is nothing
// for them to do.
class PlanSharing {
public:
    explicit PlanSharing(RangeProcesses* processes) : processes_(processes) {}
    PlanSharing(const PlanSharing&) = delete;
    PlanSharing& operator=(const PlanSharing&) = delete;
    ~PlanSharing() { share(std::nullopt); }
    void share(const std::optional<RangePlan>& plan) {
        if (processes_ && !shared_) processes_->share_plan(plan);
        shared_ = true;
    }

private:
    RangeProcesses* processes_;
    bool shared_ = false;
};

}  // namespace

PartResult decimate_part(const DecimateSettings& s, ProgressSink& progress) {
    if (!s.part || s.part->merge())
        throw io::OptionError(Setting::kPart, "decimate_part makes a part job's part file: give a part k < K");
    check_part_settings(s);
    const PartIndex part = *s.part;
    const io::Format& out_format =
        s.output_format.empty() ? io::kTriangleStreamFormat : output_format(s.output, s.output_format);
    const io::WriteOptions& wo = s.write;
    const io::ReadOptions read = decimate_read_options(s, out_format, wo);
    io::TriangleInput in = open_decimate_input(s, read);
    const io::MeshHeader header = in.header();
    PartResult result;
    result.input_name = in.name();
    result.input_format = std::string(in.format().name);
    result.input_gzip = in.source().gzip();
    refuse_output_over_inputs(s.output, std::vector<std::string>{}, {input_files(s.input, header)});
    std::optional<CountPass> counted;
    std::optional<uint64_t> input_count = header.triangle_count;
    in.close();                      // every pass below, and the range, open the input afresh
    if (s.target && !input_count) {  // as the merge counts it (decimate_file)
        counted = count_usable_triangles(s, read, progress);
        input_count = counted->count.promised;
    }
    const decimate::Options options =
        decimation_options(s, header, result.input_name, result.input_format, input_count, progress);
    const Carried carried = carried_channels(s, header, out_format, wo, result.input_name);
    std::optional<uint64_t> cut_count = input_count ? input_count : header.triangle_estimate;
    if (!cut_count) {
        counted = count_usable_triangles(s, read, progress);
        counted->for_threads = true;
        cut_count = counted->count.promised;
    }
    const unsigned ranges = range_count(part.parts, *cut_count, s.buffer);
    refuse_other_range_count(s, part, result.input_name, *cut_count, ranges);

    const RangesJob job = ranges_job(s, read, carried, options, *cut_count, ranges);
    PartFileSink sink(s.output, part, fingerprint_file(s.input), part_plan(job, carried));
    std::atomic<bool> stop{false};
    progress.phase("decimating part " + part_text(part), std::nullopt);
    // The range's progress to the caller, who may cancel it between chunks.
    class Watched final : public RangeSink {
    public:
        Watched(PartFileSink& file, ProgressSink& progress, std::atomic<bool>& stop)
            : file_(file), progress_(progress), stop_(stop) {}
        void append(const io::TriangleChunk& chunk, double weight, Piece piece) override {
            file_.append(chunk, weight, piece);
        }
        void progress(uint64_t decimated) override {
            file_.progress(decimated);
            progress_.update(decimated);
            if (progress_.cancelled()) cancelled = stop_ = true;
        }
        void close(const RangeOutcome& outcome, std::exception_ptr error) override {
            // A cancelled range leaves no part file: its temporary file goes with the sink.
            if (!cancelled) file_.close(outcome, error);
        }
        bool cancelled = false;

    private:
        PartFileSink& file_;
        ProgressSink& progress_;
        std::atomic<bool>& stop_;
    } watched(sink, progress, stop);
    run_range(job, part.k - 1, watched, stop);
    if (watched.cancelled) throw Cancelled();
    if (sink.error()) std::rethrow_exception(sink.error());

    result.cut_triangles = *cut_count;
    result.range_first = *cut_count * (part.k - 1) / part.parts;
    result.range_end = *cut_count * part.k / part.parts;
    result.triangles_in = sink.decimated();
    result.triangles_out = sink.triangles();
    result.part_file_bytes = sink.bytes();
    if (counted) result.count_pass_seconds = counted->seconds;
    return result;
}

void run_remote_range(const DecimateSettings& s, RangeProcesses& processes) {
    const std::optional<RangePlan> plan = processes.receive_plan();
    if (!plan || processes.rank() >= plan->ranges) return;
    // The channels carried, found as process 0 found them (same file, same settings).
    const io::Format& out_format = output_format(s.output, s.output_format);
    const io::WriteOptions& wo = s.write;
    const io::ReadOptions read = decimate_read_options(s, out_format, wo);
    const Carried carried = [&] {
        io::TriangleInput in = open_decimate_input(s, read);
        return carried_channels(s, in.header(), out_format, wo, in.name());
    }();
    RangesJob job;
    job.open = [&] { return open_decimate_input(s, read); };
    job.channels = carried.channels;
    job.make_decimator = [&carried](const decimate::Options& o) {
        static const io::InputCount kNoCount;  // a range takes a ratio
        return make_decimator(o, kNoCount, carried.layout);
    };
    job.options = plan->options;
    job.cut_triangles = plan->cut_triangles;
    job.ranges = plan->ranges;
    job.stop_at_forced_write = plan->stop_at_forced_write;
    processes.send(carried.channels,
                   [&](RangeSink& sink, std::atomic<bool>& stop) { run_range(job, processes.rank() - 1, sink, stop); });
}

DecimateResult decimate_file(const DecimateSettings& s, ProgressSink& progress) {
    RangeProcesses* const processes = s.processes;
    if (processes && processes->rank() > 0)
        throw std::logic_error("decimate_file runs on MPI process 0; the others call run_remote_range");
    const std::optional<PartIndex> part = s.part;
    if (!s.merge.empty() && !part)
        throw io::OptionError(Setting::kMerge, mention(Setting::kMerge) + " gives the part files to the merge job, " +
                                                   mention(Setting::kPart) + " K/K: give " + mention(Setting::kPart) +
                                                   " too");
    if (part) {
        check_part_settings(s);
        if (!part->merge())
            throw io::OptionError(Setting::kPart, "a part job k < K writes a part file: decimate_part makes it");
    }
    PlanSharing sharing(processes);
    if (processes) {
        // Every process opens the input by its name, and each decimates a range of it as read.
        if (!is_regular_file(s.input))
            throw io::OptionError(Setting::kInput, shown_input(s.input) +
                                                       ": meshstream-mpi decimates a file that every rank opens by its "
                                                       "name; give a file, not '-' or a pipe");
        if (s.sort == SortPolicy::kAlways)
            throw io::OptionError(Setting::kSort, mention(Setting::kSort) + " always" +
                                                      ": a sorted stream is decimated by one process; sort first "
                                                      "(meshstream sort IN SORTED.stl), then decimate the sorted file");
    }
    const io::Format& out_format = output_format(s.output, s.output_format);
    io::WriteOptions wo = s.write;
    const io::ReadOptions read = decimate_read_options(s, out_format, wo);
    io::TriangleInput in = open_decimate_input(s, read);
    std::optional<CountPass> counted;
    if (s.target && !in.header().triangle_count && is_regular_file(s.input)) {
        in.close();  // one reader at a time: PLY and OBJ keep vertex tables
        counted = count_usable_triangles(s, read, progress);
        in = open_decimate_input(s, read);
    }
    // The count the decimator works from: the header's, or the first pass's.
    const auto decimator_count = [&](const io::InputCount& read_loop) -> const io::InputCount& {
        return counted ? counted->count : read_loop;
    };
    const io::MeshHeader header = in.header();
    const std::string input_name = in.name();
    DecimateResult result;
    result.input_format = std::string(in.format().name);
    result.input_gzip = in.source().gzip();
    const std::optional<uint64_t> input_count = counted ? counted->count.promised : header.triangle_count;
    const decimate::Options options =
        decimation_options(s, header, input_name, in.format().name, input_count, progress);
    const Carried carried = carried_channels(s, header, out_format, wo, input_name);
    wo.channels = carried.channels;
    if (carried.channels.material) wo.materials = header.materials;

    // Threads (or MPI processes, or parts): a file cut into ranges of triangles (ranges.hpp) by the
    // count its header states or estimates, else by one counted in a first pass (not for a file
    // too small to be cut, judged by its size: any format takes 8 bytes a triangle or more,
    // uncompressed).
    const bool sort_first = s.sort == SortPolicy::kAlways;
    std::optional<uint64_t> cut_count = input_count ? input_count : header.triangle_estimate;
    const unsigned cut_into = processes ? processes->count() : part ? part->parts : s.threads;
    unsigned ranges = 1;
    if (cut_into > 1 && !sort_first && is_regular_file(s.input)) {
        const uint64_t bytes = in.source().stored_size().value_or(0);
        const uint64_t most = in.source().gzip() ? std::numeric_limits<uint64_t>::max() : bytes / 8;
        // The merge counts whatever the size, to say how many ranges the input makes.
        if (!cut_count && (most >= 2 * uint64_t(s.buffer) || part)) {
            in.close();
            counted = count_usable_triangles(s, read, progress);
            counted->for_threads = true;
            in = open_decimate_input(s, read);
            cut_count = counted->count.promised;
        }
        if (cut_count) ranges = range_count(cut_into, *cut_count, s.buffer);
    }
    // The ranges' outputs wait in the temporary directory: where nothing can be written, one
    // thread decimates (the merge of parts fails: its ranges were decimated elsewhere).
    std::string one_thread_why;
    if (ranges > 1) {
        try {
            io::TempFile probe(s.read.tmpdir, "meshstream-range");
        } catch (const io::Error& e) {
            if (part) throw;
            ranges = 1;
            one_thread_why = e.raw_what();
        }
    }
    // The merge: its plan is the parts' (each part file says it was made with it), read before
    // anything is written; in range order.
    std::vector<std::unique_ptr<PartFileReader>> part_files;
    if (part) {
        if (!cut_count)
            throw io::OptionError(Setting::kPart, input_name + ": " + mention(Setting::kPart) +
                                                      " needs the input's triangle count, which it cannot find");
        refuse_other_range_count(s, *part, input_name, *cut_count, ranges);
        const PartPlan plan = part_plan(ranges_job(s, read, carried, options, *cut_count, ranges), carried);
        const InputFingerprint fingerprint = fingerprint_file(s.input);
        part_files.resize(part->parts - 1);
        for (const std::string& path : s.merge) {
            auto file = std::make_unique<PartFileReader>(path, part->parts, fingerprint, plan);
            std::unique_ptr<PartFileReader>& slot = part_files[file->k() - 1];
            if (slot)
                throw io::OptionError(Setting::kMerge, path + ": part " + std::to_string(file->k()) + "/" +
                                                           std::to_string(part->parts) + " is given twice, as " +
                                                           slot->path() + " too");
            slot = std::move(file);
        }
    }

    // The output count, for whole-mesh writers to refuse a memory budget too small before the
    // work (and to say how much the output needs when it passes the budget): from the header's
    // count, a PLY's faces (each at least one triangle) or the count of the first pass.
    if (const std::optional<uint64_t> in_count = cut_count)
        wo.expected_triangle_count =
            options.target ? *options.target : decimate::StreamDecimator::expected_output(options.ratio, *in_count);
    // No output count is promised to the writer: the decimator lands on round(p·N_in) except
    // when the in-core rest is closed and one triangle too many is left (collapses remove two
    // faces; it then ends one over, with a warning), and skipped input triangles change N_in.
    // Writers patch their header counts at finish() (or spool when the output cannot seek).
    refuse_output_over_inputs(s.output, out_format, wo, {input_files(s.input, header)});

    // The sort: what may happen. Input known to be sorted (its flag, the caller's axis) is
    // decimated as it comes with kAuto: sorting again cannot help it, a larger buffer can.
    const bool read_once = !is_regular_file(s.input);
    // (Parts: every job decimates as read; a sort would have to be one job's.)
    const bool may_restart = s.sort == SortPolicy::kAuto && !options.sorted_axis && !part;
    const uint64_t budget = s.read.memory_budget_bytes;
    io::ReadOptions sort_ro = read;  // the reader's share while sorting
    sort_ro.memory_budget_bytes = budget / 4;
    const uint64_t sort_budget = budget / 2;
    std::optional<InputSpool> spool;
    if (read_once && (sort_first || may_restart)) spool.emplace(s.read.tmpdir, carried.channels);

    std::optional<io::Output> out(io::open_output(s.output, out_format.name, wo, s.gzip_level));
    // An output written in place cannot be taken back: it is held while a restart may come, up
    // to a quarter of the memory budget (60 bytes a triangle with vertex ids).
    HeldOutput gate(*out, out->sink->in_place() && may_restart ? std::max<uint64_t>(budget / 4 / 60, 1) : 0);
    const decimate::Emit emit = [&gate](const io::TriangleChunk& chunk) { gate.write(chunk); };
    progress.phase(sort_first ? "reading" : "decimating", input_count);

    SortOutcome outcome;
    outcome.requested = sort_first;
    std::unique_ptr<decimate::StreamDecimator> decimator;
    decimate::Options used = options;
    std::optional<SortedInput> sorted;
    std::optional<RangesResult> threaded;
    if (!sort_first && ranges > 1) {
        in.close();  // each range opens the input itself
        const auto attempt = std::chrono::steady_clock::now();
        RangesJob job = ranges_job(s, read, carried, options, *cut_count, ranges);
        job.stop_at_forced_write = may_restart;
        // Output that cannot be taken back is held until no range can call for a sort any more.
        job.seams_after_ranges = may_restart && gate.holding();
        if (processes) {
            // Range k but the last by process k+1; the last, and the seam pass, here.
            job.remote_ranges = ranges - 1;
            job.receive_remote = [processes, &carried](std::span<RangeSink* const> sinks, std::atomic<bool>& stop) {
                processes->receive(sinks, stop, carried.channels);
            };
            sharing.share(RangePlan{job.options, job.cut_triangles, job.ranges, job.stop_at_forced_write});
        }
        if (part) {
            // Ranges 0 .. K-2 from their part files, in range order, as they are read.
            job.remote_ranges = ranges - 1;
            job.receive_remote = [&part_files, &carried](std::span<RangeSink* const> sinks, std::atomic<bool>& stop) {
                for (size_t i = 0; i < sinks.size(); ++i) part_files[i]->feed(*sinks[i], stop, carried.channels);
            };
        }
        threaded = decimate_in_ranges(job, emit, progress);
        if (threaded->stopped_at_forced_write) {
            outcome.kind = SortOutcome::Kind::kSorted;
            outcome.detected_at = threaded->forced_write_at;
            outcome.attempt_seconds = seconds_since(attempt);
        }
    } else if (!sort_first) {
        sharing.share(std::nullopt);  // the other processes have nothing to do
        decimator = make_decimator(options, decimator_count(in.count()), carried.layout);
        const auto attempt = std::chrono::steady_clock::now();
        const ChunkSource next = [&](io::TriangleChunk& chunk) {
            if (!in.next(chunk)) return false;
            if (spool) spool->add(chunk);
            return true;
        };
        const bool whole = decimate_pass(
            next, carried.channels, *decimator, emit,
            [&] { progress.update(in.count().read, in.source().stored_offset(), in.source().stored_size()); },
            [&] {
                return may_restart && decimator->stats().forced_writes > 0 && !gate.released() &&
                       (!spool || spool->ok());
            },
            progress);
        if (!whole) {
            outcome.kind = SortOutcome::Kind::kSorted;
            outcome.detected_at = in.count().read;
            outcome.attempt_seconds = seconds_since(attempt);
        } else if (may_restart && decimator->stats().forced_writes > 0) {
            outcome.kind = SortOutcome::Kind::kCouldNot;
            outcome.why_not = spool && !spool->ok()
                                  ? "its spool could not be written: " + spool->error()
                                  : "its output to " + out->sink->name() + " was already under way (" +
                                        human_count(double(gate.held_triangles())) +
                                        " triangles held back first; write to a file, or sort first)";
        }
    }
    if (sort_first || outcome.kind == SortOutcome::Kind::kSorted) {
        sharing.share(std::nullopt);
        threaded.reset();  // the sorted stream is decimated by one thread
        if (decimator || outcome.kind == SortOutcome::Kind::kSorted) {
            // The attempt is dropped: its decimator, and its output (held back, or a
            // temporary file that a new one replaces).
            decimator.reset();
            if (gate.holding()) {
                gate.discard();
            } else {
                out.reset();
                out.emplace(io::open_output(s.output, out_format.name, wo, s.gzip_level));
                gate.rebind(*out);
            }
        }
        if (!read_once) in.close();
        const auto sorting = std::chrono::steady_clock::now();
        try {
            sorted = spool ? sort_spooled(in, *spool, sort_budget, s.read.tmpdir, progress, carried.channels)
                           : sort_file(s, sort_budget, sort_ro, progress, carried.channels);
        } catch (const io::Error& e) {
            // A sort kAuto chose may fail (a full temporary directory) where decimating as read
            // would not: the file is then decimated as it is. A spooled stdin is gone with the
            // spool.
            if (sort_first || spool) throw;
            outcome.kind = SortOutcome::Kind::kCouldNot;
            outcome.why_not = std::string("sorting failed: ") + e.raw_what();
        }
        gate.release();  // no restart after this one
        if (sorted) {
            outcome.kind = SortOutcome::Kind::kSorted;
            outcome.axis = sorted->axis;
            outcome.sort_seconds = seconds_since(sorting);
            outcome.temp_bytes = sorted->temp_bytes;
            used.sorted_axis = sorted->axis;
            used.sorted_by_minimum = true;
            decimator = make_decimator(used, decimator_count(sorted->count), carried.layout);
            progress.phase("decimating the sorted input", sorted->count.passed());
            uint64_t done = 0;
            const ChunkSource next = [&](io::TriangleChunk& chunk) {
                if (!sorted->sorter->next(chunk)) return false;
                done += chunk.size();
                return true;
            };
            decimate_pass(
                next, carried.channels, *decimator, emit, [&] { progress.update(done); }, {}, progress);
        } else {
            in = open_decimate_input(s, read);
            decimator = make_decimator(options, decimator_count(in.count()), carried.layout);
            progress.phase("decimating", input_count);
            decimate_pass(
                [&](io::TriangleChunk& chunk) { return in.next(chunk); }, carried.channels, *decimator, emit,
                [&] { progress.update(in.count().read, in.source().stored_offset(), in.source().stored_size()); }, {},
                progress);
        }
    }
    progress.phase("finishing", std::nullopt);
    if (decimator) decimator->finish(emit);
    gate.release();
    // A reader may have added materials while reading (OBJ: names met after the first face).
    const io::MeshHeader& end_header = sorted ? sorted->end_header : threaded ? threaded->end_header : in.header();
    if (carried.channels.material) out->writer->update_materials(end_header.materials);
    out->finish();

    DecimateFacts& facts = result.facts;
    facts.stats = threaded ? threaded->stats : decimator->stats();
    facts.ratio = threaded ? threaded->ratio : decimator->ratio();
    facts.threads = threaded && !processes && !part ? ranges : 1;
    if (part) facts.parts = ranges;
    if (processes) facts.processes = threaded ? ranges : 1;
    if (threaded) {
        facts.seam_buffer = decimate::seam_pass_buffer(s.buffer);
        facts.seam_forced_writes = threaded->seams.forced_writes;
    }
    facts.target_given = options.target.has_value();
    facts.buffer = s.buffer;
    facts.default_buffer = s.buffer == decimate::kDefaultBufferTriangles;
    facts.given_axis = s.sorted_axis;
    facts.file_axis = header.sorted_axis;
    facts.used_axis = used.sorted_axis;
    facts.weld_eps = options.weld_eps;
    facts.skipped = sorted ? sorted->count.dropped : threaded ? threaded->count.dropped : in.count().dropped;
    facts.input_name = input_name;
    facts.sort = outcome;
    if (counted) {
        facts.count_pass_seconds = counted->seconds;
        facts.count_pass_for_threads = counted->for_threads;
    }

    Warnings& warnings = result.warnings;
    // The kinds not asked for were not read: their loss goes unsaid.
    if (!carried.dropped.empty())
        warnings.note("channels_dropped", dropped_channels_text(carried.dropped, *out->format, carried.channels));
    if (!carried.rounded.empty())
        warnings.note("channels_rounded", "vertex scalars " + carried.rounded +
                                              " carried through decimation as float: values rounded to about 7 "
                                              "significant digits");
    for (const std::string& note : out->writer->raw_notes()) warnings.note("output_note", note);
    note_dropped_triangles(sorted     ? sorted->dropped
                           : threaded ? threaded->dropped
                                      : dropped_triangles(in),
                           "skipped", warnings);
    note_input_changes(end_header, input_name, warnings);
    if (!one_thread_why.empty())
        warnings.note("threads_unavailable",
                      "decimated by one thread: the ranges' outputs cannot be spooled (" + one_thread_why + ")");

    result.output_format = std::string(out->format->name);
    result.output_gzip = s.output != "-" && io::wants_gzip(s.output);
    result.triangles_in = sorted ? sorted->count.read : threaded ? threaded->count.read : in.count().read;
    result.triangles_out = facts.stats.triangles_out;
    for (const auto& f : part_files)
        result.part_files.push_back({f->path(), f->k(), f->outcome().stats.triangles_in, f->triangles()});
    return result;
}

}  // namespace meshstream::engine
