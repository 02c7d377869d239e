// `meshstream decimate IN OUT --ratio p`: the Wu & Kobbelt stream decimator (decimate/) between
// any reader and writer of the registry. Memory: the decimator's fixed buffer (--buffer) plus
// what the two formats need; the output streams while the input is still being read.
#include "decimate/phase_timers.hpp"
#include "decimate/stream_decimator.hpp"
#include "io/error.hpp"
#include "tools/cli_checks.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/input_filter.hpp"
#include "compare/metro.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <new>
#include <stdexcept>

namespace meshstream::tools {
namespace {

using compare::CompareOptions;
using compare::CompareResult;
using compare::compare_meshes;
using compare::file_source;

struct DecimateOptions {
    std::string input, output;
    std::optional<double> ratio;
    std::optional<uint64_t> target;
    size_t buffer = 400000;
    int candidates = 8;
    uint64_t seed = 1;
    std::string weld;  // "" / "0.001" / "0.01%"
    std::optional<int> sorted_axis;
    bool report = false;
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
        throw UsageError(input_name + ": --weld " + text + " needs the bounding box, found in a first pass over the "
                                       "input, which a stream cannot be read twice for; give an absolute size instead");
    const io::Bounds box = input_bounds(opt.input, opt.read.from, opt.read.options());
    double diag2 = 0;
    for (int i = 0; i < 3; ++i) {
        const double d = double(box.max[i]) - box.min[i];
        diag2 += d * d;
    }
    return std::isfinite(diag2) ? value / 100 * std::sqrt(diag2) : 0;  // no finite corner: nothing to weld
}

void run_decimate(const DecimateOptions& opt) {
    const auto start = std::chrono::steady_clock::now();
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
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, Command::kDecimate);
    const io::MeshHeader& header = in.header();

    decimate::Options options;
    if (opt.target) {
        // Options that cannot work with this input: exit 2, like the command line's own errors.
        if (!header.triangle_count)
            throw UsageError(in.name() + ": --target needs the input triangle count, which this format does "
                                                 "not state up front (binary STL, Draco and glTF do); use --ratio");
        if (*opt.target > *header.triangle_count)
            throw UsageError(in.name() + ": --target " + std::to_string(*opt.target) + " is more than the " +
                             std::to_string(*header.triangle_count) +
                             " triangles of the input (decimation only removes triangles)");
        options.target = *opt.target;
    } else {
        options.ratio = opt.ratio.value_or(0.1);
    }
    options.buffer_triangles = opt.buffer;
    options.candidates = opt.candidates;
    options.seed = opt.seed;
    options.weld_eps = weld_epsilon(opt, in.name());
    options.sorted_axis = opt.sorted_axis ? opt.sorted_axis : header.sorted_axis;
    // The file's flag comes from `meshstream sort` (or a convert that kept its order): ascending
    // by triangle minimum. A --sorted-axis of the user's own says less: the key is not known.
    options.sorted_by_minimum = header.sorted_axis && options.sorted_axis == header.sorted_axis;
    std::unique_ptr<decimate::StreamDecimator> made;  // on the heap only to catch a refused reservation here
    try {
        made = std::make_unique<decimate::StreamDecimator>(options, in.count());
    } catch (const std::bad_alloc&) {
        throw std::runtime_error(
            "--buffer " + std::to_string(opt.buffer) + " reserves " +
            human_bytes(double(decimate::HalfEdgeBuffer::reserved_bytes(opt.buffer))) +
            " of memory (about 500 bytes a triangle), which this system refused: give a smaller --buffer (the "
            "default 400000 reserves " + human_bytes(double(decimate::HalfEdgeBuffer::reserved_bytes(400000))) + ")");
    }
    decimate::StreamDecimator& decimator = *made;

    io::WriteOptions wo = opt.write.options(opt.read);
    // The output count, for whole-mesh writers to refuse a --memory too small before the work.
    if (header.triangle_count)
        wo.expected_triangle_count = options.target ? *options.target
                                                    : decimate::StreamDecimator::expected_output(options.ratio, *header.triangle_count);
    // No output count is promised to the writer: the decimator lands on round(p·N_in) except
    // when the in-core rest is closed and one triangle too many is left (collapses remove two
    // faces; it then ends one over, with a warning), and skipped input triangles change N_in.
    // Writers patch their header counts at finish() (or spool when the output cannot seek).
    refuse_output_over_inputs(opt.output, out_format, wo, {input_files(opt.input, header)});
    io::Output out = io::open_output(opt.output, out_format.name, wo, opt.write.gzip_level);

    const decimate::Emit emit = [&out](const io::TriangleChunk& chunk) { out.write(chunk); };
    // The decimator rates and writes positions only: no other channel is read.
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, io::Channels{});
    Progress progress("decimating", header.triangle_count);
    while (in.next(chunk)) {
        decimator.push(chunk, emit);
        progress.update(in.count().read);
    }
    progress.phase("finishing", std::nullopt);
    decimator.finish(emit);
    progress.done();
    out.finish();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const decimate::Stats& s = decimator.stats();
    std::fprintf(stderr, "decimated %s -> %s\n", in.name().c_str(), opt.output.c_str());
    std::fprintf(stderr, "  triangles in %llu, out %llu (target %llu, ratio %.6g)\n",
                 (unsigned long long)s.triangles_in, (unsigned long long)s.triangles_out,
                 (unsigned long long)s.target_triangles, decimator.ratio());
    std::fprintf(stderr, "  time %.3f s, %s input triangles/s, peak RSS %s\n", seconds,
                 human_count(seconds > 0 ? double(s.triangles_in) / seconds : 0).c_str(),
                 human_bytes(double(peak_rss_bytes())).c_str());
    std::fprintf(stderr, "  buffer %zu triangles, peak fill %zu (%.1f %%), collapses %llu, forced writes %llu\n",
                 s.buffer_capacity, s.peak_buffer_triangles,
                 100.0 * double(s.peak_buffer_triangles) / double(s.buffer_capacity),
                 (unsigned long long)s.collapses, (unsigned long long)s.forced_writes);
    if (options.weld_eps > 0)
        std::fprintf(stderr, "  weld %.6g: %llu vertices merged\n", options.weld_eps,
                     (unsigned long long)s.vertices_merged);
    if (options.sorted_axis)
        std::fprintf(stderr, "  sorted along %c (%s): %llu hole-boundary vertices finalized by the sweep\n",
                     "xyz"[*options.sorted_axis],
                     s.sweep_direction > 0 ? "ascending" : s.sweep_direction < 0 ? "descending" : "direction not seen",
                     (unsigned long long)s.vertices_finalized_by_sweep);
    decimate::print_phase_report(stderr);  // only in builds with MESHSTREAM_PHASE_TIMERS

    Warnings warnings;
    if (const std::string dropped = io::describe_missing(header.channels, io::Channels{}); !dropped.empty())
        warnings.note(dropped + " dropped: decimate keeps positions only");
    char ratio_text[32];
    std::snprintf(ratio_text, sizeof ratio_text, "%.6g", decimator.ratio());
    // The command that judges this run's buffer (info assumes the default one).
    const std::string order_command = "`meshstream info --order --ratio " + std::string(ratio_text) +
                                      (opt.buffer != DecimateOptions{}.buffer ? " --buffer " + std::to_string(opt.buffer) : "") + "`";
    note_unused_write_flags(opt.write, *out.format, opt.output, warnings);
    for (const std::string& note : out.writer->notes()) warnings.note(note);
    const uint64_t skipped = in.count().dropped;
    note_dropped_triangles(dropped_triangles(in), "skipped", warnings);
    note_input_changes(in.header(), in.name(), warnings);
    const bool axis_conflict = opt.sorted_axis && header.sorted_axis && *opt.sorted_axis != *header.sorted_axis;
    if (axis_conflict)
        warnings.note(std::string("--sorted-axis ") + "xyz"[*opt.sorted_axis] + " was given, but " + in.name() +
                      " says it is sorted along " + "xyz"[*header.sorted_axis] + ": the sweep used " +
                      "xyz"[*opt.sorted_axis] + ", as given");
    if (s.forced_writes > 0)
        warnings.note("buffer full of undecimatable triangles: " + std::to_string(s.forced_writes) +
                     " triangles force-written at full resolution (" +
                     std::to_string(s.premature_writes) +
                     " written before reaching the target resolution; near them a few triangles may come out twice, "
                     "back to back)" +
                     (s.orphans_evicted > 0
                          ? "; " + std::to_string(s.orphans_evicted) +
                                " of their vertices were evicted from the weld table to make room, so triangles "
                                "read later at those positions are not joined to them (the output has cracks there)"
                          : std::string()) +
                     (axis_conflict
                          ? std::string("; --sorted-axis overrode the axis the file gives (see below)")
                      : options.sorted_axis && s.sort_violations == 0 && s.sweep_direction == 0
                          ? std::string("; the input is said to be sorted along ") + "xyz"[*options.sorted_axis] +
                                ", but its triangles never moved along it by more than three of their lengths, so the "
                                "sweep that finalizes hole boundaries never started: check the axis (" + order_command +
                                " counts the key descents along each)"
                      : options.sorted_axis && s.sort_violations == 0
                          ? "; the input is sorted, so the buffer is too small for it at this ratio: raise --buffer (" +
                                order_command + " estimates the buffer it needs)"
                          : "; either the input is not in streaming order (run `meshstream sort` on it first) or the "
                            "buffer is too small for it at this ratio (raise --buffer): " + order_command + " tells which"));
    if (s.sort_violations > 0)
        warnings.note(std::string("the input is not sorted along ") + "xyz"[*options.sorted_axis] +
                     " as stated: " + std::to_string(s.sort_violations) +
                     (s.sort_violations == 1 ? " triangle" : " triangles") +
                     " reached behind the sweep, which was switched off at the first (boundary finalized before it "
                     "may show as cracks); " +
                     (axis_conflict ? std::string("leave out --sorted-axis to use the file's own axis")
                                    : std::string("run `meshstream sort` on it first")));
    if (s.nonmanifold_edges > 0)
        warnings.add("non-manifold, duplicate or mis-oriented edges frozen and passed through", s.nonmanifold_edges);
    if (s.degenerate_passed > 0)
        warnings.add("degenerate triangles (repeated corners) passed through", s.degenerate_passed);
    if (s.weld_dropped > 0) warnings.add("triangles dropped because --weld merged their corners", s.weld_dropped);
    // Welding that collapses many triangles is coarser than the mesh: it removes surface
    // detail the decimation would have kept.
    if (options.weld_eps > 0 && s.weld_dropped * 100 > s.triangles_in)
        warnings.note("--weld " + opt.weld + " welded the corners of " +
                      std::to_string(s.weld_dropped * 100 / s.triangles_in) +
                      " % of the triangles together: it is coarser than the mesh; weld on a smaller size");
    // Triangles that share no corners exactly (cracks from float round-off, a soup written
    // triangle by triangle) leave every edge open: decimation then eats the surface from every
    // crack and still lands on its count. A mesh has far fewer open edges than triangles (a
    // strip one triangle wide about one per triangle); a soup has three. (A few loose triangles
    // are no surface to warn about; an input without triangles: the filter's report says so.)
    if (s.triangles_in >= 100 && s.boundary_edges * 2 > s.triangles_in * 3)
        warnings.note(std::to_string(s.boundary_edges) + " edges had no partner, " +
                      std::to_string(s.boundary_edges / s.triangles_in) + "." +
                      std::to_string(s.boundary_edges * 10 / s.triangles_in % 10) +
                      " per triangle: the triangles share few corners exactly (an unwelded surface?), and "
                      "decimation removes surface along every open edge; --weld EPS snaps corners to a grid of EPS");
    const std::string missed = "output has " + std::to_string(s.triangles_out) + " triangles instead of the target " +
                               std::to_string(s.target_triangles);
    // Skipped triangles that come late leave --target short: the part read before them was
    // decimated for the larger input the header promised.
    const std::string skipped_late = std::to_string(skipped) +
                                     " input triangles were skipped (above), most of them after the part before "
                                     "them had been decimated for the larger input the header promised; `meshstream "
                                     "convert --clean` drops them into a copy that lands on the target";
    if (s.triangles_in > 0 && s.target_triangles > s.triangles_in)
        warnings.note("the target " + std::to_string(s.target_triangles) + " is more than the " +
                      std::to_string(s.triangles_in) + " usable input triangles: " +
                      (s.collapses == 0 ? std::string("nothing was decimated") : missed + "; " + skipped_late));
    else if (options.target && s.triangles_in > 0 && s.triangles_out < s.target_triangles && skipped > 0)
        warnings.note(missed + " (" + skipped_late + ")");
    else if (s.triangles_in > 0 && s.triangles_out == s.target_triangles + 1)
        warnings.note(missed + " (a collapse removes two triangles, and no boundary edge could be collapsed to remove the odd one)");
    else if (s.triangles_in > 0 && s.triangles_out != s.target_triangles && s.forced_writes > 0)
        warnings.note(missed + " (the triangles force-written at full resolution, above, count against it)");
    else if (s.triangles_in > 0 && s.triangles_out != s.target_triangles && s.no_valid_collapse_left)
        warnings.note(missed + " (no allowed collapse is left: each would fold a face over or change the topology, "
                               "or move a vertex that must stay, as on a non-manifold edge)");
    else if (s.triangles_in > 0 && s.triangles_out > s.target_triangles && s.nonmanifold_edges > 0)
        warnings.note(missed + " (the " + std::to_string(s.nonmanifold_edges) +
                      " non-manifold, duplicate or mis-oriented edges above are frozen with their vertices: "
                      "faces wound against their neighbours join none of them)");
    else if (s.triangles_in > 0 && s.triangles_out != s.target_triangles)
        warnings.note(missed + " (too little left that could be decimated)");
    else if (s.triangles_in > 0 && s.target_triangles == 0)
        warnings.note("the target rounds to 0 triangles (" + std::to_string(s.triangles_in) +
                      " in): the output is empty; give a larger --ratio or --target");
    warnings.print();

    if (opt.report) {
        // An output without triangles (or only zero-area ones) has nothing to compare: that is
        // said, and the written output stands (compare itself refuses such a mesh).
        if (s.triangles_out == 0) {
            std::fprintf(stderr, "  error vs input: not measured (the output has no triangles)\n");
            return;
        }
        CompareOptions co;
        co.memory_budget_bytes = opt.read.options().memory_budget_bytes;
        co.tmpdir = opt.read.tmpdir;
        const CompareResult r = compare_meshes(file_source(opt.input, opt.read.from, opt.read.options()),
                                               file_source(opt.output, {}, opt.read.options()), co);
        if (r.a_to_b.samples == 0 && r.b_to_a.samples == 0) {
            std::fprintf(stderr, "  error vs input: not measured (no samples: the triangles have no area)\n");
            return;
        }
        const double diag = r.diagonal > 0 ? r.diagonal : 1;
        std::fprintf(stderr, "  error vs input (%% of bbox diagonal %.6g): Hausdorff %.6g (%.4f %%), mean %.6g (%.4f %%), "
                             "rms %.6g (%.4f %%)\n", r.diagonal, r.hausdorff(), 100 * r.hausdorff() / diag,
                     r.mean(), 100 * r.mean() / diag, r.rms(), 100 * r.rms() / diag);
    }
}

}  // namespace

void add_decimate(CLI::App& app) {
    auto opt = std::make_shared<DecimateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "decimate", "Decimate a mesh of any size in one streaming pass (Wu & Kobbelt 2003) with a fixed memory buffer.\n"
                    "Output size is round(ratio x input), or --target: exactly, unless the mesh cannot get there\n"
                    "(one more when an odd number is left to remove at the end and no boundary edge can be\n"
                    "collapsed to remove a single triangle; a warning says so).");
    cmd->add_option("input", opt->input, "Input mesh ('-' = stdin)")->required();
    cmd->add_option("output", opt->output, "Output mesh ('-' = stdout: a pipe gets meshstream's triangle stream, anything else needs --to)")->required();
    auto* ratio = cmd->add_option("-r,--ratio", opt->ratio, "Fraction of input triangles to keep, in (0, 1] (default 0.1)")
                      ->check(open_unit_interval());
    cmd->add_option("--target", opt->target, "Exact output triangle count (needs a format that states the input count)")
        ->excludes(ratio)
        ->check(whole_number(1, "a whole number of triangles"));
    cmd->add_option("--buffer", opt->buffer, "In-core buffer capacity in triangles (memory is fixed by it)")
        ->capture_default_str()->check(CLI::Range(size_t{16}, size_t{1} << 29));
    cmd->add_option("--candidates", opt->candidates, "Multiple-choice sample size for collapses and writes")
        ->capture_default_str()->check(CLI::Range(1, 64));
    cmd->add_option("--seed", opt->seed, "Random seed (same input, options and seed give identical output)")
        ->capture_default_str()->check(whole_number(0, "a whole number"));
    cmd->add_option("--weld", opt->weld, "Weld vertices on a grid of this size (absolute, or N% of the bbox diagonal)");
    cmd->add_option("--sorted-axis", opt->sorted_axis,
                    "The input is sorted along this axis: x, y or z (or 0, 1, 2); read from the file when it says so")
        ->transform(CLI::Validator(
            [](std::string& text) -> std::string {
                static const std::map<std::string, std::string> kAxes = {
                    {"x", "0"}, {"y", "1"}, {"z", "2"}, {"X", "0"}, {"Y", "1"}, {"Z", "2"},
                    {"0", "0"}, {"1", "1"}, {"2", "2"}};
                const auto it = kAxes.find(text);
                if (it == kAxes.end()) return "must be x, y or z (or 0, 1, 2), found '" + text + "'";
                text = it->second;
                return {};
            },
            "x|y|z"));
    cmd->add_flag("--report", opt->report, "Compare the output against the input (Hausdorff, mean, RMS) at the end");
    add_read_flags(cmd, opt->read);
    strict_refuses_dropped_triangles(cmd);
    add_write_flags(cmd, opt->write);
    cmd->callback([opt] { run_decimate(*opt); });
}

}  // namespace meshstream::tools
