// `meshstream decimate IN OUT --ratio p`: the command line of engine::decimate_file (the Wu &
// Kobbelt stream decimator between any reader and writer, on every core, sorting on demand:
// engine/decimate.hpp). This file turns the flags into DecimateSettings, draws the progress, and
// prints the summary, the warnings and --json; --report measures the output against the input.
#include "engine/decimate.hpp"
#include "compare/metro.hpp"
#include "io/error.hpp"
#include "io/triangle_stream.hpp"
#include "tools/cli_checks.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/decimate_report.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/jobs.hpp"
#include "tools/run_report.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

namespace meshstream::tools {

using engine::parse_part;
using engine::PartIndex;
using engine::RangeProcesses;

namespace {

using compare::compare_meshes;
using compare::CompareOptions;
using compare::CompareResult;
using compare::file_source;

// --weld EPS: absolute, or "P%" of the bounding-box diagonal.
engine::Weld parse_weld(const std::string& text) {
    engine::Weld weld;
    if (text.empty()) return weld;
    weld.of_diagonal = text.back() == '%';
    const std::string number = weld.of_diagonal ? text.substr(0, text.size() - 1) : text;
    size_t used = 0;
    try {
        weld.size = std::stod(number, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    // All of it: "1,5" used to weld on a grid of 1 (the whole bunny to one point), "1mm" of 1.
    if (used == 0 || used != number.size())
        throw CLI::ValidationError("--weld", "expected a number or a percentage, found '" + text + "'");
    if (!(weld.size >= 0) || !std::isfinite(weld.size))
        throw CLI::ValidationError("--weld", "must be a non-negative number, found '" + text + "'");
    return weld;
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

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
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

// The job the flags describe. `out_format`: the output's (for a part job, the merge's, or null
// for the triangle stream).
engine::DecimateSettings settings_of(const DecimateOptions& opt, const io::Format* out_format,
                                     RangeProcesses* processes) {
    engine::DecimateSettings s;
    s.input = opt.input;
    s.output = opt.output;
    s.input_format = opt.read.from;
    if (out_format) s.output_format = std::string(out_format->name);
    s.ratio = opt.ratio;
    s.target = opt.target;
    s.buffer = opt.buffer;
    s.weld = parse_weld(opt.weld);
    s.sorted_axis = opt.sorted_axis;
    s.sort = opt.sort == "always"  ? engine::SortPolicy::kAlways
             : opt.sort == "never" ? engine::SortPolicy::kNever
                                   : engine::SortPolicy::kAuto;
    s.threads = processes || !opt.part.empty() ? 1 : opt.threads;
    s.weights = parse_weights(opt.weights);
    s.seed = opt.seed;
    s.read = opt.read.options();
    s.write = opt.write.options(opt.read, out_format ? *out_format : io::kTriangleStreamFormat);
    s.gzip_level = opt.write.gzip_level;
    if (!opt.part.empty()) s.part = parse_part(opt.part);  // checked by the option
    s.merge = opt.merge;
    s.processes = processes;
    return s;
}

// --part k/K with k < K: range k-1 of the plan --threads K makes, decimated into the part file
// OUT. The channels carried are the ones the merge's output keeps: --to's format's, else every
// channel of the input (less --drop).
nlohmann::ordered_json decimate_part(const DecimateOptions& opt, engine::ProgressSink* progress) {
    const auto start = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    const io::Format* out_format = opt.write.to.empty() ? nullptr : &resolve_output_format(opt.output, opt.write);
    const engine::DecimateSettings settings = settings_of(opt, out_format, nullptr);
    engine::PartResult part;
    {
        std::optional<Progress> bar;
        part = engine::decimate_part(settings, progress ? *progress : bar.emplace("decimating", std::nullopt));
    }
    const double seconds = seconds_since(start);
    // The range's figures; the merge reports the whole decimation (its warnings included).
    if (!opt.json && !global().quiet) {
        std::fprintf(stderr, "decimated part %s of %s -> %s\n", opt.part.c_str(), part.input_name.c_str(),
                     opt.output.c_str());
        std::fprintf(stderr, "  range: triangles [%llu, %llu) of %llu, decimated to %llu (%s in the part file)\n",
                     (unsigned long long)part.range_first, (unsigned long long)part.range_end,
                     (unsigned long long)part.cut_triangles, (unsigned long long)part.triangles_out,
                     human_bytes(double(part.part_file_bytes)).c_str());
        std::fprintf(stderr, "  time %.3f s, peak RSS %s; merge with --part %u/%u\n", seconds,
                     human_bytes(double(peak_rss_bytes())).c_str(), settings.part->parts, settings.part->parts);
    }
    RunReport report;
    report.command = "decimate";
    report.inputs = {{opt.input, part.input_format, part.input_gzip}};
    report.outputs = {{opt.output, "part", false}};
    report.triangles_in = part.triangles_in;
    report.triangles_out = part.triangles_out;
    report.seconds = seconds;
    report.peak_rss_bytes = peak_rss_bytes();
    report.details = {{"part", settings.part->k},
                      {"parts", settings.part->parts},
                      {"range_first", part.range_first},
                      {"range_end", part.range_end},
                      {"part_file_bytes", part.part_file_bytes}};
    return run_report_json(report, Warnings{});
}

// The checks of flags that go together only on the command line (the library refuses the rest
// itself, in its own words).
void refuse_flag_combinations(const DecimateOptions& opt, const std::optional<PartIndex>& part) {
    if (!opt.merge.empty() && !part)
        throw UsageError("--merge gives the part files to the merge job, --part K/K: give --part too");
    if (!part) return;
    const std::string both = "--part " + opt.part;
    if (opt.threads_given)
        throw UsageError(both + " decimates one range of the input in this job; --threads does not go with it");
    if (!part->merge() && opt.report)
        throw UsageError(both + " writes a part file, not a mesh: give --report to the merge job");
}

}  // namespace

nlohmann::ordered_json decimate_job(const DecimateOptions& opt, RangeProcesses* processes,
                                    engine::ProgressSink* progress) {
    std::optional<PartIndex> part;
    if (!opt.part.empty()) part = parse_part(opt.part);  // checked by the option
    if (processes && processes->rank() > 0) {
        const io::Format& out_format = resolve_output_format(opt.output, opt.write);
        engine::run_remote_range(settings_of(opt, &out_format, processes), *processes);
        return nullptr;
    }
    refuse_flag_combinations(opt, part);
    if (part && !part->merge()) {
        // The library checks the rest of the part job's settings; these go first as before.
        return decimate_part(opt, progress);
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
    const engine::DecimateSettings settings = settings_of(opt, &out_format, processes);
    engine::DecimateResult result;
    double seconds = 0;
    {
        std::optional<Progress> bar;
        result = engine::decimate_file(
            settings, progress ? *progress
                               : bar.emplace(settings.sort == engine::SortPolicy::kAlways ? "reading" : "decimating",
                                             std::nullopt));
        seconds = seconds_since(start);
    }
    DecimateFacts& facts = result.facts;
    facts.weld_text = opt.weld;
    if (!opt.json && !global().quiet) print_decimate_summary(facts, opt.output, seconds);

    Warnings warnings = result.warnings;
    note_unused_write_flags(opt.write, out_format, opt.output, warnings);
    note_decimate_warnings(facts, warnings);
    print_warnings(warnings);

    RunReport report = run_report_of("decimate", opt.input, opt.output, result, seconds);
    report.details = decimate_details_json(facts);
    if (part) {
        nlohmann::ordered_json files = nlohmann::ordered_json::array();
        for (const engine::PartFileFacts& f : result.part_files)
            files.push_back(
                {{"path", f.path}, {"part", f.k}, {"triangles_in", f.triangles_in}, {"triangles", f.triangles}});
        report.details["part_files"] = files;
    }
    if (opt.report) report.details["error"] = report_error(opt, facts);
    return run_report_json(report, warnings);
}

CLI::App* decimate_command(CLI::App& app, DecimateOptions& options, RangeProcesses* processes) {
    DecimateOptions* opt = &options;
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
                    "in-core buffer in triangles, which fixes the memory (default " +
                        std::to_string(decimate::kDefaultBufferTriangles) +
                        ")\n"
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
    if (!processes) {
        add_threads_option(cmd, opt->threads, "decimate a file in N ranges at once",
                           "Each range of at least --buffer triangles is decimated with its own --buffer, and the "
                           "seams between them are joined by one more pass; the output depends on N, not on timing");
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
    return cmd;
}

void add_decimate(CLI::App& app, RangeProcesses* processes) {
    auto opt = std::make_shared<DecimateOptions>();
    CLI::App* cmd = decimate_command(app, *opt, processes);
    const CLI::Option* threads = cmd->get_option_no_throw("--threads");
    run_when_parsed(cmd, opt, [processes, threads](DecimateOptions& o) {
        o.threads_given = threads && threads->count() > 0;
        return decimate_job(o, processes);
    });
}

}  // namespace meshstream::tools
