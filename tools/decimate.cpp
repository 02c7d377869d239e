// `meshstream decimate IN OUT --ratio p`: the Wu & Kobbelt stream decimator (decimate/) between
// any reader and writer of the registry. Memory: the decimator's fixed buffer (--buffer) plus
// what the two formats need; the output streams while the input is still being read.
//
// --sort auto (the default): input not known to be sorted is decimated as it comes until the
// first forced write, the sign that it is in no streaming order the buffer can hold. Then the
// attempt is dropped (a file output's temporary file, or the output held back for a pipe), the
// input is sorted out of core (sort/external_sort.hpp, within half of --memory, runs in
// --tmpdir), from the file again or from a spool of stdin written meanwhile, and the sorted
// stream is decimated. Input in streaming order costs nothing extra (an order pass, as
// `info --order` makes, would read the whole file first); --sort always sorts first, never as
// read.
#include "compare/metro.hpp"
#include "decimate/stream_decimator.hpp"
#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/triangle_stream.hpp"
#include "sort/external_sort.hpp"
#include "tools/cli_checks.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/decimate_parts.hpp"
#include "tools/decimate_report.hpp"
#include "tools/decimate_threads.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/run_report.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <stdexcept>
#include <thread>

namespace meshstream::tools {
namespace {

using compare::compare_meshes;
using compare::CompareOptions;
using compare::CompareResult;
using compare::file_source;

struct DecimateOptions {
    std::string input, output;
    std::optional<double> ratio;
    std::optional<uint64_t> target;
    size_t buffer = 400000;
    uint64_t seed = 1;
    std::string weld;  // "" / "0.001" / "0.01%"
    std::optional<int> sorted_axis;
    std::string sort = "auto";  // --sort auto|always|never
    unsigned threads = every_core();
    bool threads_given = false;      // --threads given (else every core)
    std::string part;                // --part k/K
    std::vector<std::string> merge;  // --merge PART ... (the merge job, --part K/K)
    std::string weights;             // --weights normal=W,color=W,uv=W,NAME=W
    bool report = false;
    bool json = false;
    ReadFlags read;
    WriteFlags write;
};

// --weld EPS: absolute, or "P%" of the bounding-box diagonal, found by a first pass over the
// input (a regular file only: a stream cannot be read twice).
double weld_epsilon(const DecimateOptions& opt, const std::string& input_name) {
    const std::string& text = opt.weld;
    if (text.empty()) return 0;
    const bool percent = text.back() == '%';
    double value = 0;
    const std::string number = percent ? text.substr(0, text.size() - 1) : text;
    size_t used = 0;
    try {
        value = std::stod(number, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    // All of it: "1,5" used to weld on a grid of 1 (the whole bunny to one point), "1mm" of 1.
    if (used == 0 || used != number.size())
        throw CLI::ValidationError("--weld", "expected a number or a percentage, found '" + text + "'");
    if (!(value >= 0) || !std::isfinite(value))
        throw CLI::ValidationError("--weld", "must be a non-negative number, found '" + text + "'");
    if (!percent) return value;
    if (!is_regular_file(opt.input))
        throw UsageError(input_name + ": --weld " + text +
                         " needs the bounding box, found in a first pass over the "
                         "input, which a stream cannot be read twice for; give an absolute size instead");
    const io::Bounds box = input_bounds(opt.input, opt.read.from, opt.read.options());
    double diag2 = 0;
    for (int i = 0; i < 3; ++i) {
        const double d = double(box.max[i]) - box.min[i];
        diag2 += d * d;
    }
    return std::isfinite(diag2) ? value / 100 * std::sqrt(diag2) : 0;  // no finite corner: nothing to weld
}

// --weights: "normal=0.5,color=1,uv=2,intensity=1" (colour also as colour/colors, normal as
// normals, uv as uvs; any other name is a vertex scalar's).
decimate::AttributeWeights parse_weights(const std::string& text) {
    decimate::AttributeWeights w;
    if (text.empty()) return w;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t end = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, end - start);
        const size_t eq = item.find('=');
        if (eq == std::string::npos || eq == 0)
            throw CLI::ValidationError("--weights",
                                       "expected NAME=WEIGHT items separated by commas, found '" + item + "'");
        const std::string name = item.substr(0, eq), number = item.substr(eq + 1);
        double value = 0;
        size_t used = 0;
        try {
            value = std::stod(number, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != number.size() || !(value >= 0) || !std::isfinite(value))
            throw CLI::ValidationError("--weights", name + ": expected a number >= 0, found '" + number + "'");
        if (name == "normal" || name == "normals")
            w.normal = value;
        else if (name == "color" || name == "colour" || name == "colors" || name == "colours")
            w.color = value;
        else if (name == "uv" || name == "uvs")
            w.uv = value;
        else
            w.scalars.emplace_back(name, value);
        start = end + 1;
    }
    return w;
}

// What the decimator carries from input to output: the channels read (less --drop's) that the
// output format keeps, as an attribute layout; and what is dropped for the output's sake.
struct Carried {
    io::Channels channels;  // what the reader fills and the writer gets (no vertex ids)
    decimate::AttributeLayout layout;
    std::string dropped;  // in words; empty when nothing is
    // Vertex scalars whose type float cannot hold exactly (the decimator keeps a corner's values
    // as float), in words; empty when none.
    std::string rounded;
};

Carried carried_channels(const DecimateOptions& opt, const io::MeshHeader& header, const io::Format& out_format,
                         const io::WriteOptions& wo, const std::string& input_name) {
    Carried c;
    // What --drop leaves (the reader may read less: nothing, for an output that keeps nothing).
    io::Channels wanted = opt.read.options().channels.of(header.channels);
    wanted.vertex_id = false;
    c.channels = io::writable_channels(out_format, wanted, wo);
    c.channels.vertex_id = false;
    c.dropped = io::describe_missing(wanted, c.channels);
    try {
        c.layout = decimate::AttributeLayout(c.channels, parse_weights(opt.weights));
    } catch (const std::invalid_argument& e) {
        throw UsageError(input_name + ": --weights: " + e.what());
    }
    if (c.layout.size() > decimate::kMaxAttributeComponents)
        throw UsageError(input_name + ": " + std::to_string(c.layout.size()) +
                         " normal, colour, texture and scalar values per corner, more than the " +
                         std::to_string(decimate::kMaxAttributeComponents) +
                         " decimate carries: leave some out with --drop extra (or uvs)");
    for (const io::ScalarChannel& s : c.channels.vertex_scalars)
        if (s.type == io::ScalarType::kFloat64 || s.type == io::ScalarType::kInt32 || s.type == io::ScalarType::kUInt32)
            c.rounded += (c.rounded.empty() ? "'" : ", '") + s.name + "' (" + io::scalar_type_name(s.type) + ")";
    return c;
}

// What a decimation pass reads: fills a chunk, false at the end.
using ChunkSource = std::function<bool(io::TriangleChunk&)>;

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Every triangle read from an input that can be read once only (stdin, a pipe), spooled to a
// temporary file so that it can still be sorted: its positions and the channels decimate
// carries (TriangleRecords: 36 bytes a triangle plus those), with the bounding box of its finite
// coordinates. The file is made on the first add(); a file that cannot be made or written stops
// the spool (ok() false, error() says why) instead of failing the command, which then decimates
// the input as it comes.
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
            error_ = e.what();
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
    TriangleRecords records_;
    std::vector<char> bytes_;
    std::unique_ptr<io::TempFile> file_;
    std::string error_;
    io::Bounds box_;
    uint64_t triangles_ = 0, read_ = 0;
};

// Where the decimator's output goes while decimate may still start over on sorted input. A
// file output is written as it comes (a restart drops its temporary file); an output written
// in place (stdout, a pipe) is held in memory up to `hold_triangles`, then written out: from
// there on nothing can be taken back (released()).
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

// The decimator's options from the command line and the input's header. `input_count` is the
// header's triangle count, or the one a first pass counted. Options that cannot work with this
// input are UsageErrors (exit 2).
decimate::Options decimation_options(const DecimateOptions& opt, const io::MeshHeader& header, const std::string& name,
                                     std::string_view format, std::optional<uint64_t> input_count) {
    decimate::Options options;
    if (opt.target) {
        if (!input_count)
            throw UsageError(name + ": --target needs the input triangle count, which " + std::string(format) +
                             " does not state up front (binary STL, Draco and glTF do), and a stream cannot be "
                             "read twice to count it: give the input as a file, or use --ratio");
        if (*opt.target > *input_count)
            throw UsageError(name + ": --target " + std::to_string(*opt.target) + " is more than the " +
                             std::to_string(*input_count) +
                             " triangles of the input (decimation only removes triangles)");
        options.target = *opt.target;
    } else {
        options.ratio = opt.ratio.value_or(0.1);
    }
    options.buffer_triangles = opt.buffer;
    options.seed = opt.seed;
    options.weld_eps = weld_epsilon(opt, name);
    options.sorted_axis = opt.sorted_axis ? opt.sorted_axis : header.sorted_axis;
    // The file's flag comes from `meshstream sort` (or a convert that kept its order): ascending
    // by triangle minimum. A --sorted-axis of the user's own says less: the key is not known.
    options.sorted_by_minimum = header.sorted_axis && options.sorted_axis == header.sorted_axis;
    return options;
}

// --target for a file whose header states no triangle count (OBJ, ASCII STL, PLY, whose faces
// may be polygons): the triangles decimate can use, counted in a first pass with the same
// read loop (positions only), handed to the decimator as promised with none dropped; and what
// the pass cost.
struct CountPass {
    io::InputCount count;
    double seconds = 0;
    bool for_threads = false;  // made to cut the input into ranges (else for --target)
};

CountPass count_usable_triangles(const DecimateOptions& opt, const io::ReadOptions& read) {
    const auto start = std::chrono::steady_clock::now();
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, io::Channels{});
    Progress progress("counting triangles for --target", std::nullopt);
    while (in.next(chunk)) progress.update(in.count().read, in.source());
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
        throw std::runtime_error(
            "--buffer " + std::to_string(options.buffer_triangles) + " reserves " + human_bytes(double(bytes)) +
            " of memory (about " + std::to_string(bytes / std::max<size_t>(options.buffer_triangles, 1)) +
            " bytes a triangle), which this system refused: give a smaller --buffer (the "
            "default 400000 reserves " +
            human_bytes(double(decimate::StreamDecimator::reserved_bytes(400000, attributes))) + ")");
    }
}

// Pushes what `next` gives through `decimator`, calling `show_progress` after each chunk;
// returns false when `stop`, asked after each chunk, said to stop, true at the end of the input.
bool decimate_pass(const ChunkSource& next, const io::Channels& channels, decimate::StreamDecimator& decimator,
                   const decimate::Emit& emit, const std::function<void()>& show_progress,
                   const std::function<bool()>& stop) {
    // The chunk carries what the decimator does: the reader fills no more.
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (next(chunk)) {
        decimator.push(chunk, emit);
        show_progress();
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
                                                  Progress& progress, const io::Channels& channels = {}) {
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
SortedInput sort_file(const DecimateOptions& opt, uint64_t sort_budget, const io::ReadOptions& ro,
                      const std::string& tmpdir, Progress& progress, const io::Channels& channels) {
    SortedInput s;
    s.axis = longest_axis(input_bounds(opt.input, opt.read.from, ro));
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, ro, Command::kDecimate);
    s.sorter = make_sorter(s.axis, sort_budget, tmpdir, progress, channels);
    progress.phase("sorting: reading", in.header().triangle_count);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (in.next(chunk)) {
        s.sorter->add(chunk);
        progress.update(in.count().read, in.source());
    }
    s.count = in.count();
    s.dropped = dropped_triangles(in);
    s.end_header = in.header();
    in.close();
    s.sorter->finish_input();
    s.temp_bytes = s.sorter->stats().peak_temp_bytes;
    return s;
}

// Sorts an input read once: the rest of it goes to the spool, which is then sorted.
SortedInput sort_spooled(io::TriangleInput& in, InputSpool& spool, uint64_t sort_budget, const std::string& tmpdir,
                         Progress& progress, const io::Channels& channels) {
    progress.phase("spooling the input", in.header().triangle_count);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (in.next(chunk)) {
        spool.add(chunk);
        progress.update(in.count().read, in.source());
    }
    if (!spool.ok()) throw io::Error(in.name(), "cannot spool the input to sort it: " + spool.error());
    SortedInput s;
    s.count = in.count();
    s.dropped = dropped_triangles(in);
    s.end_header = in.header();
    s.axis = longest_axis(spool.bounds());
    s.sorter = make_sorter(s.axis, sort_budget, tmpdir, progress, channels);
    progress.phase("sorting: reading the spool", s.count.passed());
    uint64_t done = 0;
    while (spool.next(chunk)) {
        s.sorter->add(chunk);
        progress.update(done += chunk.size());
    }
    s.sorter->finish_input();
    s.temp_bytes = spool.bytes() + s.sorter->stats().peak_temp_bytes;
    return s;
}

// --report: the output compared against the input, printed on stderr (unless --json); the
// figures for --json (null when not measured).
nlohmann::ordered_json report_error(const DecimateOptions& opt, const DecimateFacts& facts) {
    // An output without triangles (or only zero-area ones) has nothing to compare: that is
    // said, and the written output stands (compare itself refuses such a mesh).
    if (facts.stats.triangles_out == 0) {
        if (!opt.json) std::fprintf(stderr, "  error vs input: not measured (the output has no triangles)\n");
        return nullptr;
    }
    CompareOptions co;
    co.memory_budget_bytes = opt.read.options().memory_budget_bytes;
    co.tmpdir = opt.read.tmpdir;
    const CompareResult r = compare_meshes(file_source(opt.input, opt.read.from, opt.read.options()),
                                           file_source(opt.output, {}, opt.read.options()), co);
    if (r.a_to_b.samples == 0 && r.b_to_a.samples == 0) {
        if (!opt.json)
            std::fprintf(stderr, "  error vs input: not measured (no samples: the triangles have no area)\n");
        return nullptr;
    }
    const double diag = r.diagonal > 0 ? r.diagonal : 1;
    if (!opt.json)
        std::fprintf(stderr,
                     "  error vs input (%% of bbox diagonal %.6g): Hausdorff %.6g (%.4f %%), mean %.6g (%.4f %%), "
                     "rms %.6g (%.4f %%)\n",
                     r.diagonal, r.hausdorff(), 100 * r.hausdorff() / diag, r.mean(), 100 * r.mean() / diag, r.rms(),
                     100 * r.rms() / diag);
    return {{"bbox_diagonal", r.diagonal}, {"hausdorff", r.hausdorff()}, {"mean", r.mean()}, {"rms", r.rms()}};
}

// The read loop decimate reads through: the channels --drop leaves, when the output format can
// keep any (decimate carries them); else none, so that the reader stores no attribute (a
// coloured PLY decimated to STL costs what a plain one does), while the header still lists what
// is dropped.
io::ReadOptions decimate_read_options(const DecimateOptions& opt, const io::Format& out_format,
                                      const io::WriteOptions& wo) {
    io::ReadOptions read = opt.read.options();
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

// The ranges of `ranges` of an input of `cut_triangles` triangles (--threads, meshstream-mpi,
// --part): every job that decimates a range of the input plans it here, so that their plans agree.
RangesJob ranges_job(const DecimateOptions& opt, const io::ReadOptions& read, const Carried& carried,
                     const decimate::Options& options, uint64_t cut_triangles, unsigned ranges) {
    RangesJob job;
    job.open = [&opt, &read] { return open_triangle_input(opt.input, opt.read, read, Command::kDecimate); };
    job.make_decimator = [&carried](const decimate::Options& o) {
        static const io::InputCount kNoCount;  // a range and the seam pass take a ratio
        return make_decimator(o, kNoCount, carried.layout);
    };
    job.tmpdir = opt.read.tmpdir;
    job.channels = carried.channels;
    job.options = options;
    job.options.target.reset();
    if (options.target) job.options.ratio = std::min(1.0, double(*options.target) / double(cut_triangles));
    job.target = options.target;
    job.cut_triangles = cut_triangles;
    job.ranges = ranges;
    return job;
}

// What a part file records of the plan, for the merge to check (decimate_parts.hpp).
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

// --part k/K: the input must be cut into exactly K ranges, as --threads K would cut it.
void refuse_other_range_count(const DecimateOptions& opt, PartIndex part, const std::string& input_name,
                              uint64_t cut_triangles, unsigned ranges) {
    if (ranges == part.parts) return;
    if (opt.buffer < kMinRangeBuffer)
        throw UsageError("--part " + opt.part + ": a --buffer below " + std::to_string(kMinRangeBuffer) +
                         " is never cut into ranges (--buffer " + std::to_string(opt.buffer) + ")");
    throw UsageError(input_name + ": " + std::to_string(cut_triangles) + " triangles through --buffer " +
                     std::to_string(opt.buffer) + " make at most " + std::to_string(ranges) +
                     (ranges == 1 ? " range" : " ranges") + " (each holds at least --buffer triangles), not " +
                     std::to_string(part.parts) + ": " +
                     (ranges >= 2 ? "use --part k/" + std::to_string(ranges) + " or a smaller --buffer"
                                  : std::string("the input is too small to cut; decimate it in one job")));
}

// --part k/K with k < K: range k-1 of the plan --threads K makes, decimated into the part file
// OUT. The channels carried are the ones the merge's output keeps: --to's format's, else every
// channel of the input (less --drop).
void decimate_part(const DecimateOptions& opt, PartIndex part) {
    const auto start = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    const io::Format& out_format =
        opt.write.to.empty() ? io::kTriangleStreamFormat : resolve_output_format(opt.output, opt.write);
    const io::WriteOptions wo = opt.write.options(opt.read, out_format);
    const io::ReadOptions read = decimate_read_options(opt, out_format, wo);
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
    const io::MeshHeader header = in.header();
    const std::string input_name = in.name();
    const std::string format_name(in.format().name);
    const RunFile input_file{opt.input, format_name, in.source().gzip()};
    refuse_output_over_inputs(opt.output, std::vector<std::string>{}, {input_files(opt.input, header)});
    std::optional<CountPass> counted;
    std::optional<uint64_t> input_count = header.triangle_count;
    in.close();                        // every pass below, and the range, open the input afresh
    if (opt.target && !input_count) {  // as the merge counts it (run_decimate)
        counted = count_usable_triangles(opt, read);
        input_count = counted->count.promised;
    }
    const decimate::Options options = decimation_options(opt, header, input_name, format_name, input_count);
    const Carried carried = carried_channels(opt, header, out_format, wo, input_name);
    std::optional<uint64_t> cut_count = input_count ? input_count : header.triangle_estimate;
    if (!cut_count) {
        counted = count_usable_triangles(opt, read);
        counted->for_threads = true;
        cut_count = counted->count.promised;
    }
    const unsigned ranges = range_count(part.parts, *cut_count, opt.buffer);
    refuse_other_range_count(opt, part, input_name, *cut_count, ranges);

    const RangesJob job = ranges_job(opt, read, carried, options, *cut_count, ranges);
    PartFileSink sink(opt.output, part, fingerprint_file(opt.input), part_plan(job, carried));
    std::atomic<bool> stop{false};
    run_range(job, part.k - 1, sink, stop);
    if (sink.error()) std::rethrow_exception(sink.error());
    const double seconds = seconds_since(start);

    // The range's figures; the merge reports the whole decimation (its warnings included).
    const uint64_t first = *cut_count * (part.k - 1) / part.parts, end = *cut_count * part.k / part.parts;
    const uint64_t in_range = sink.decimated();
    if (!opt.json && !global().quiet) {
        std::fprintf(stderr, "decimated part %s of %s -> %s\n", opt.part.c_str(), input_name.c_str(),
                     opt.output.c_str());
        std::fprintf(stderr, "  range: triangles [%llu, %llu) of %llu, decimated to %llu (%s in the part file)\n",
                     (unsigned long long)first, (unsigned long long)end, (unsigned long long)*cut_count,
                     (unsigned long long)sink.triangles(), human_bytes(double(sink.bytes())).c_str());
        std::fprintf(stderr, "  time %.3f s, peak RSS %s; merge with --part %u/%u\n", seconds,
                     human_bytes(double(peak_rss_bytes())).c_str(), part.parts, part.parts);
    }
    if (opt.json) {
        RunReport report;
        report.command = "decimate";
        report.inputs = {input_file};
        report.outputs = {{opt.output, "part", false}};
        report.triangles_in = in_range;
        report.triangles_out = sink.triangles();
        report.seconds = seconds;
        report.peak_rss_bytes = peak_rss_bytes();
        report.details = {{"part", part.k},
                          {"parts", part.parts},
                          {"range_first", first},
                          {"range_end", end},
                          {"part_file_bytes", sink.bytes()}};
        print_json(run_report_json(report, Warnings{}));
    }
}

// meshstream-mpi, every process but the first: the range process 0's plan gives it, decimated
// and sent to process 0 (which reports everything, failures included).
void decimate_one_range(const DecimateOptions& opt, RangeProcesses& processes) {
    const std::optional<RangePlan> plan = processes.receive_plan();
    if (!plan || processes.rank() >= plan->ranges) return;
    // The channels carried, found as process 0 found them (same file, same options).
    const io::Format& out_format = resolve_output_format(opt.output, opt.write);
    const io::WriteOptions wo = opt.write.options(opt.read, out_format);
    const io::ReadOptions read = decimate_read_options(opt, out_format, wo);
    const Carried carried = [&] {
        io::TriangleInput in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
        return carried_channels(opt, in.header(), out_format, wo, in.name());
    }();
    RangesJob job;
    job.open = [&] { return open_triangle_input(opt.input, opt.read, read, Command::kDecimate); };
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

// meshstream-mpi, process 0: the other processes wait for the plan, so they are told once,
// whatever happens: the plan, or (when this ends without one, a failure included) that there is
// nothing for them to do.
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

void run_decimate(const DecimateOptions& opt, RangeProcesses* processes) {
    if (processes && processes->rank() > 0) return decimate_one_range(opt, *processes);
    std::optional<PartIndex> part;
    if (!opt.part.empty()) part = parse_part(opt.part);  // checked by the option
    if (!opt.merge.empty() && !part)
        throw UsageError("--merge gives the part files to the merge job, --part K/K: give --part too");
    if (part) {
        const std::string both = "--part " + opt.part;
        if (opt.threads_given)
            throw UsageError(both + " decimates one range of the input in this job; --threads does not go with it");
        // Every job opens IN by its name and reads it from its start to its range.
        if (!is_regular_file(opt.input))
            throw UsageError((opt.input == "-" ? std::string("<stdin>") : opt.input) + ": " + both +
                             ": every job reads IN from its start, so IN must be a file, not '-' or a pipe");
        if (opt.sort == "always")
            throw UsageError(both +
                             ": --sort always decimates a sorted stream in one job; sort first (meshstream sort IN "
                             "SORTED.stl), then make the parts from the sorted file");
        if (!part->merge()) {
            if (!opt.merge.empty())
                throw UsageError("--merge goes with the merge job, --part " + std::to_string(part->parts) + "/" +
                                 std::to_string(part->parts) + ", not " + both);
            if (opt.report) throw UsageError(both + " writes a part file, not a mesh: give --report to the merge job");
            return decimate_part(opt, *part);
        }
        if (opt.merge.size() != part->parts - 1)
            throw UsageError(both + " merges parts 1/" + std::to_string(part->parts) + " to " +
                             std::to_string(part->parts - 1) + "/" + std::to_string(part->parts) +
                             ": give --merge once for each of their " + std::to_string(part->parts - 1) +
                             " part files, found " + std::to_string(opt.merge.size()));
    }
    PlanSharing sharing(processes);
    if (processes) {
        // Every process opens the input by its name, and each decimates a range of it as read.
        if (!is_regular_file(opt.input))
            throw UsageError((opt.input == "-" ? std::string("<stdin>") : opt.input) +
                             ": meshstream-mpi decimates a file that every rank opens by its name; give a file, "
                             "not '-' or a pipe");
        if (opt.sort == "always")
            throw UsageError(
                "--sort always: a sorted stream is decimated by one process; sort first (meshstream sort IN "
                "SORTED.stl), then decimate the sorted file");
    }
    const auto start = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    // Checked before any work: the comparison re-reads both files once the output is done.
    const io::Format& out_format = resolve_output_format(opt.output, opt.write);
    if (opt.report) {
        const bool input_stream = is_stream(opt.input);
        if (input_stream || is_stream(opt.output)) {
            const std::string name = input_stream ? (opt.input == "-" ? "<stdin>" : opt.input)
                                                  : (opt.output == "-" ? "<stdout>" : opt.output);
            throw UsageError(name + ": --report needs to re-read both files; it does not work with '-' or a pipe");
        }
    }
    io::WriteOptions wo = opt.write.options(opt.read, out_format);
    const io::ReadOptions read = decimate_read_options(opt, out_format, wo);
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
    std::optional<CountPass> counted;
    if (opt.target && !in.header().triangle_count && is_regular_file(opt.input)) {
        in.close();  // one reader at a time: PLY and OBJ keep vertex tables
        counted = count_usable_triangles(opt, read);
        in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
    }
    // The count the decimator works from: the header's, or the first pass's.
    const auto decimator_count = [&](const io::InputCount& read_loop) -> const io::InputCount& {
        return counted ? counted->count : read_loop;
    };
    const io::MeshHeader header = in.header();
    const std::string input_name = in.name();
    const RunFile input_file{opt.input, std::string(in.format().name), in.source().gzip()};
    const std::optional<uint64_t> input_count = counted ? counted->count.promised : header.triangle_count;
    const decimate::Options options = decimation_options(opt, header, input_name, in.format().name, input_count);
    const Carried carried = carried_channels(opt, header, out_format, wo, input_name);
    wo.channels = carried.channels;
    if (carried.channels.material) wo.materials = header.materials;

    // --threads (or meshstream-mpi's processes): a file cut into ranges of triangles
    // (decimate_threads.hpp) by the count its header states or estimates, else by one counted in
    // a first pass (not for a file too small to be cut, judged by its size: any format takes 8
    // bytes a triangle or more, uncompressed).
    const bool sort_first = opt.sort == "always";
    std::optional<uint64_t> cut_count = input_count ? input_count : header.triangle_estimate;
    const unsigned cut_into = processes ? processes->count() : part ? part->parts : opt.threads;
    unsigned ranges = 1;
    if (cut_into > 1 && !sort_first && is_regular_file(opt.input)) {
        const uint64_t bytes = in.source().stored_size().value_or(0);
        const uint64_t most = in.source().gzip() ? std::numeric_limits<uint64_t>::max() : bytes / 8;
        // The merge counts whatever the size, to say how many ranges the input makes.
        if (!cut_count && (most >= 2 * uint64_t(opt.buffer) || part)) {
            in.close();
            counted = count_usable_triangles(opt, read);
            counted->for_threads = true;
            in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
            cut_count = counted->count.promised;
        }
        if (cut_count) ranges = range_count(cut_into, *cut_count, opt.buffer);
    }
    // The ranges' outputs wait in --tmpdir: where nothing can be written, one thread decimates
    // (the merge of --part fails: its ranges were decimated elsewhere).
    std::string one_thread_why;
    if (ranges > 1) {
        try {
            io::TempFile probe(opt.read.tmpdir, "meshstream-range");
        } catch (const io::Error& e) {
            if (part) throw;
            ranges = 1;
            one_thread_why = e.what();
        }
    }
    // The merge: its plan is the parts' (each part file says it was made with it), read before
    // anything is written; in range order.
    std::vector<std::unique_ptr<PartFileReader>> part_files;
    if (part) {
        if (!cut_count)
            throw UsageError(input_name + ": --part needs the input's triangle count, which it cannot find");
        refuse_other_range_count(opt, *part, input_name, *cut_count, ranges);
        const PartPlan plan = part_plan(ranges_job(opt, read, carried, options, *cut_count, ranges), carried);
        const InputFingerprint fingerprint = fingerprint_file(opt.input);
        part_files.resize(part->parts - 1);
        for (const std::string& path : opt.merge) {
            auto file = std::make_unique<PartFileReader>(path, part->parts, fingerprint, plan);
            std::unique_ptr<PartFileReader>& slot = part_files[file->k() - 1];
            if (slot)
                throw UsageError(path + ": part " + std::to_string(file->k()) + "/" + std::to_string(part->parts) +
                                 " is given twice, as " + slot->path() + " too");
            slot = std::move(file);
        }
    }

    // The output count, for whole-mesh writers to refuse a --memory too small before the work
    // (and to say how much the output needs when it passes the budget): from the header's
    // count, a PLY's faces (each at least one triangle) or the count of the first pass.
    if (const std::optional<uint64_t> in_count = cut_count)
        wo.expected_triangle_count =
            options.target ? *options.target : decimate::StreamDecimator::expected_output(options.ratio, *in_count);
    // No output count is promised to the writer: the decimator lands on round(p·N_in) except
    // when the in-core rest is closed and one triangle too many is left (collapses remove two
    // faces; it then ends one over, with a warning), and skipped input triangles change N_in.
    // Writers patch their header counts at finish() (or spool when the output cannot seek).
    refuse_output_over_inputs(opt.output, out_format, wo, {input_files(opt.input, header)});

    // --sort: what may happen. Input known to be sorted (its flag, --sorted-axis) is decimated
    // as it comes in auto: sorting again cannot help it, a larger buffer can.
    const bool read_once = !is_regular_file(opt.input);
    // (--part: every job decimates as read; a sort would have to be one job's.)
    const bool may_restart = opt.sort == "auto" && !options.sorted_axis && !part;
    const uint64_t budget = opt.read.options().memory_budget_bytes;
    io::ReadOptions sort_ro = read;  // the reader's share while sorting
    sort_ro.memory_budget_bytes = budget / 4;
    const uint64_t sort_budget = budget / 2;
    std::optional<InputSpool> spool;
    if (read_once && (sort_first || may_restart)) spool.emplace(opt.read.tmpdir, carried.channels);

    std::optional<io::Output> out(io::open_output(opt.output, out_format.name, wo, opt.write.gzip_level));
    // An output written in place cannot be taken back: it is held while a restart may come, up
    // to a quarter of --memory (60 bytes a triangle with vertex ids).
    HeldOutput gate(*out, out->sink->in_place() && may_restart ? std::max<uint64_t>(budget / 4 / 60, 1) : 0);
    const decimate::Emit emit = [&gate](const io::TriangleChunk& chunk) { gate.write(chunk); };
    Progress progress(sort_first ? "reading" : "decimating", input_count);

    SortOutcome outcome;
    outcome.requested = sort_first;
    std::unique_ptr<decimate::StreamDecimator> decimator;
    decimate::Options used = options;
    std::optional<SortedInput> sorted;
    std::optional<RangesResult> threaded;
    if (!sort_first && ranges > 1) {
        in.close();  // each range opens the input itself
        const auto attempt = std::chrono::steady_clock::now();
        RangesJob job = ranges_job(opt, read, carried, options, *cut_count, ranges);
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
        threaded = decimate_in_ranges(job, emit, [&](uint64_t done) { progress.update(done); });
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
            next, carried.channels, *decimator, emit, [&] { progress.update(in.count().read, in.source()); },
            [&] {
                return may_restart && decimator->stats().forced_writes > 0 && !gate.released() &&
                       (!spool || spool->ok());
            });
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
                out.emplace(io::open_output(opt.output, out_format.name, wo, opt.write.gzip_level));
                gate.rebind(*out);
            }
        }
        if (!read_once) in.close();
        const auto sorting = std::chrono::steady_clock::now();
        try {
            sorted = spool ? sort_spooled(in, *spool, sort_budget, opt.read.tmpdir, progress, carried.channels)
                           : sort_file(opt, sort_budget, sort_ro, opt.read.tmpdir, progress, carried.channels);
        } catch (const io::Error& e) {
            // A sort auto chose may fail (a full --tmpdir) where decimating as read would not:
            // the file is then decimated as it is. A spooled stdin is gone with the spool.
            if (sort_first || spool) throw;
            outcome.kind = SortOutcome::Kind::kCouldNot;
            outcome.why_not = std::string("sorting failed: ") + e.what();
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
            decimate_pass(next, carried.channels, *decimator, emit, [&] { progress.update(done); }, {});
        } else {
            in = open_triangle_input(opt.input, opt.read, read, Command::kDecimate);
            decimator = make_decimator(options, decimator_count(in.count()), carried.layout);
            progress.phase("decimating", input_count);
            decimate_pass([&](io::TriangleChunk& chunk) { return in.next(chunk); }, carried.channels, *decimator, emit,
                          [&] { progress.update(in.count().read, in.source()); }, {});
        }
    }
    progress.phase("finishing", std::nullopt);
    if (decimator) decimator->finish(emit);
    gate.release();
    // A reader may have added materials while reading (OBJ: names met after the first face).
    if (carried.channels.material)
        out->writer->update_materials((sorted     ? sorted->end_header
                                       : threaded ? threaded->end_header
                                                  : in.header())
                                          .materials);
    progress.done();
    out->finish();
    const double seconds = seconds_since(start);

    DecimateFacts facts;
    facts.stats = threaded ? threaded->stats : decimator->stats();
    facts.ratio = threaded ? threaded->ratio : decimator->ratio();
    facts.threads = threaded && !processes && !part ? ranges : 1;
    if (part) facts.parts = ranges;
    if (processes) facts.processes = threaded ? ranges : 1;
    if (threaded) {
        facts.seam_buffer = seam_buffer(opt.buffer);
        facts.seam_forced_writes = threaded->seams.forced_writes;
    }
    facts.target_given = options.target.has_value();
    facts.buffer = opt.buffer;
    facts.default_buffer = opt.buffer == DecimateOptions{}.buffer;
    facts.given_axis = opt.sorted_axis;
    facts.file_axis = header.sorted_axis;
    facts.used_axis = used.sorted_axis;
    facts.weld_eps = options.weld_eps;
    facts.weld_text = opt.weld;
    facts.skipped = sorted ? sorted->count.dropped : threaded ? threaded->count.dropped : in.count().dropped;
    facts.input_name = input_name;
    facts.sort = outcome;
    if (counted) {
        facts.count_pass_seconds = counted->seconds;
        facts.count_pass_for_threads = counted->for_threads;
    }
    if (!opt.json && !global().quiet) print_decimate_summary(facts, opt.output, seconds);

    Warnings warnings;
    // --drop's channels were not read: their loss was asked for, so it goes unsaid.
    if (!carried.dropped.empty())
        warnings.note("channels_dropped", dropped_channels_text(carried.dropped, *out->format, carried.channels));
    if (!carried.rounded.empty())
        warnings.note("channels_rounded", "vertex scalars " + carried.rounded +
                                              " carried through decimation as float: values rounded to about 7 "
                                              "significant digits");
    note_unused_write_flags(opt.write, *out->format, opt.output, warnings);
    for (const std::string& note : out->writer->notes()) warnings.note("output_note", note);
    note_dropped_triangles(sorted     ? sorted->dropped
                           : threaded ? threaded->dropped
                                      : dropped_triangles(in),
                           "skipped", warnings);
    note_input_changes(sorted     ? sorted->end_header
                       : threaded ? threaded->end_header
                                  : in.header(),
                       input_name, warnings);
    note_decimate_warnings(facts, warnings);
    if (!one_thread_why.empty())
        warnings.note("threads_unavailable",
                      "decimated by one thread: the ranges' outputs cannot be spooled (" + one_thread_why + ")");
    warnings.print();

    RunReport report;
    report.command = "decimate";
    report.inputs = {input_file};
    report.outputs = {{opt.output, std::string(out->format->name), opt.output != "-" && io::wants_gzip(opt.output)}};
    report.triangles_in = sorted ? sorted->count.read : threaded ? threaded->count.read : in.count().read;
    report.triangles_out = facts.stats.triangles_out;
    report.seconds = seconds;
    report.peak_rss_bytes = peak_rss_bytes();
    report.details = decimate_details_json(facts);
    if (part) {
        nlohmann::ordered_json files = nlohmann::ordered_json::array();
        for (const auto& f : part_files)
            files.push_back({{"path", f->path()},
                             {"part", f->k()},
                             {"triangles_in", f->outcome().stats.triangles_in},
                             {"triangles", f->triangles()}});
        report.details["part_files"] = files;
    }
    if (opt.report) report.details["error"] = report_error(opt, facts);
    if (opt.json) print_json(run_report_json(report, warnings));
}

}  // namespace

void add_decimate(CLI::App& app, RangeProcesses* processes) {
    auto opt = std::make_shared<DecimateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "decimate", "decimate a mesh of any size in one streaming pass, in fixed memory\n" + kInOutText);
    cmd->add_option("IN", opt->input, "input mesh ('-' = stdin)")->required();
    cmd->add_option("OUT", opt->output, "output mesh ('-' = stdout)")->required();
    auto* ratio =
        cmd->add_option("-r,--ratio", opt->ratio,
                        "fraction of the triangles to keep, in (0, 1] (default 0.1)\n"
                        "The output has round(ratio x input) triangles: exactly, unless the mesh cannot get "
                        "there (one more when an odd number is left to remove at the end and no boundary edge "
                        "can be collapsed to remove a single triangle; a warning says so)")
            ->type_name("P")
            ->check(open_unit_interval());
    cmd->add_option("--target", opt->target,
                    "exact output triangle count, instead of --ratio\n"
                    "An input that states no count is counted in a first pass (not from a pipe)")
        ->type_name("N")
        ->excludes(ratio)
        ->check(whole_number(1, "a whole number of triangles"));
    cmd->add_option("--buffer", opt->buffer,
                    "in-core buffer in triangles, which fixes the memory (default 400000)\n"
                    "About 580 bytes a triangle; a larger buffer holds input in a poorer order")
        ->type_name("N")
        ->check(CLI::Range(size_t{16}, size_t{1} << 29));
    cmd->add_option("--weld", opt->weld, "weld corners on a grid of EPS, or of P% of the bounding-box diagonal")
        ->type_name("EPS");
    cmd->add_option("--sort", opt->sort,
                    "auto (default), always or never: sort the input first\n"
                    "auto: input not known to be sorted whose order the buffer cannot hold (forced writes) is sorted "
                    "out of core first, within half of --memory, in --tmpdir (stdin is spooled there); always: sort "
                    "first; never: decimate as read")
        ->type_name("WHEN")
        ->check(CLI::IsMember({"auto", "always", "never"}));
    cmd->add_option("--weights", opt->weights,
                    "weights of the attribute errors: normal, color, uv, or a vertex scalar's name\n"
                    "Default: 0.5 for normals, 1 for colours and texture coordinates, none for scalars. "
                    "Collapses are rated by geometric plus attribute error. A weight multiplies the values (colours "
                    "in 0..1), so the error grows with its square; 0 rates by geometry alone (values are still "
                    "interpolated); e.g. --weights color=W,normal=W")
        ->type_name("NAME=W,...")
        ->group(kMoreOptions);
    cmd->add_flag("--report", opt->report,
                  "measure the output's error against the input at the end\n"
                  "Hausdorff, mean and RMS distance, as compare does");
    CLI::Option* threads = nullptr;
    if (!processes) {
        add_threads_option(cmd, opt->threads, "decimate a file in N ranges at once",
                           "Each range of at least --buffer triangles is decimated with its own --buffer, and the "
                           "seams between them are joined by one more pass; the output depends on N, not on timing");
        threads = cmd->get_option("--threads");
        cmd->add_option("--part", opt->part,
                        "one of K jobs: k < K writes range k to the part file OUT, K/K merges them\n"
                        "The ranges of --threads K as separate jobs, every one with the same options: job k (1 .. "
                        "K-1) decimates range k of IN into the part file OUT (--to names the merge's output format, "
                        "which decides the channels carried); job K/K, with --merge, decimates the last range, joins "
                        "the parts' seams and writes OUT, the bytes --threads K writes. IN must be a file; every job "
                        "decimates as read (--sort never)")
            ->type_name("k/K")
            ->group(kMoreOptions)
            ->check(CLI::Validator(
                [](const std::string& text) -> std::string {
                    if (parse_part(text)) return {};
                    return "must be k/K with 1 <= k <= K and 2 <= K <= 1024, found '" + text + "'";
                },
                ""));
        cmd->add_option("--merge", opt->merge,
                        "a part file of --part k/K (k < K), for the merge job --part K/K\n"
                        "Once for each part, in any order; each is checked against this job's input and options "
                        "before any work")
            ->type_name("PART")
            ->allow_extra_args(false)  // one file a --merge: the next argument may be IN
            ->group(kMoreOptions);
    }
    add_json_flag(cmd, opt->json);
    add_write_flags(cmd, opt->write);
    add_read_flags(cmd, opt->read);
    add_drop_flag(cmd, opt->read);
    describe_memory_for_writing(cmd);
    cmd->get_option("--tmpdir")->group("Options");
    strict_refuses_dropped_triangles(cmd);
    cmd->add_option("--seed", opt->seed, "random seed (default 1): same input, options and seed, same output")
        ->type_name("N")
        ->group(kMoreOptions)
        ->check(whole_number(0, "a whole number"));
    cmd->add_option("--sorted-axis", opt->sorted_axis,
                    "the input is sorted along x, y or z (read from the file when it says so)")
        ->type_name("AXIS")
        ->group(kMoreOptions)
        ->transform(CLI::Validator(
            [](std::string& text) -> std::string {
                static const std::map<std::string, std::string> kAxes = {{"x", "0"}, {"y", "1"}, {"z", "2"},
                                                                         {"X", "0"}, {"Y", "1"}, {"Z", "2"},
                                                                         {"0", "0"}, {"1", "1"}, {"2", "2"}};
                const auto it = kAxes.find(text);
                if (it == kAxes.end()) return "must be x, y or z (or 0, 1, 2), found '" + text + "'";
                text = it->second;
                return {};
            },
            ""));
    cmd->footer(
        "  meshstream decimate scan.ply scan.glb -r 0.01\n"
        "  meshstream sort big.stl - | meshstream decimate - out.glb -r 0.01");
    cmd->callback([opt, processes, threads] {
        opt->threads_given = threads && threads->count() > 0;
        run_decimate(*opt, processes);
    });
}

}  // namespace meshstream::tools
