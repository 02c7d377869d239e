// `meshstream sort IN OUT`: the command line of engine::sort_file (engine/convert.hpp), the
// out-of-core pre-sorting of a triangle stream along one axis for the stream decimator
// (sort/external_sort.hpp does the sorting; docs/sorting.md explains the method and the memory
// bound). With --threads 2 or more, reading runs on a thread of its own during run generation
// and writing during the merge (io/pipeline.hpp); the output is the same.
#include "engine/convert.hpp"
#include "io/error.hpp"
#include "sort/external_sort.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/jobs.hpp"
#include "tools/run_report.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace meshstream::tools {
namespace {

const char* const kAxisNames[] = {"x", "y", "z"};

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// --stats' line: triangles, axis, time and rate, each phase's time, runs, merge passes,
// temporary disk and peak RSS.
std::string sort_stats_line(const sort::SortStats& s, int axis, double seconds, double input_seconds,
                            double sort_seconds, uint64_t peak_rss) {
    char line[512];
    std::snprintf(line, sizeof line,
                  "sorted %llu triangles along %s in %.2f s (%s triangles/s; input and runs %.2f s, "
                  "last run sort and merge passes %.2f s, final merge and output %.2f s): %s, "
                  "%d merge pass%s, %s temporary written, peak temporary disk %s, peak RSS %s",
                  (unsigned long long)s.triangles, kAxisNames[axis], seconds,
                  human_count(seconds > 0 ? double(s.triangles) / seconds : 0).c_str(), input_seconds, sort_seconds,
                  seconds - input_seconds - sort_seconds,
                  (s.runs == 0 ? "in memory (room for " + std::to_string(s.run_capacity) + " triangles), no runs"
                               : std::to_string(s.runs) + (s.runs == 1 ? " run" : " runs") + " of up to " +
                                     std::to_string(s.run_capacity))
                      .c_str(),
                  s.merge_passes, s.merge_passes == 1 ? "" : "es", human_bytes(double(s.temp_bytes_written)).c_str(),
                  human_bytes(double(s.peak_temp_bytes)).c_str(), human_bytes(double(peak_rss)).c_str());
    return line;
}

}  // namespace

nlohmann::ordered_json sort_job(const SortOptions& opt, engine::ProgressSink* progress) {
    const auto t0 = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    const io::Format& out_format = resolve_output_format(opt.output, opt.write);
    auto settings = job_settings<engine::SortSettings>(opt.input, opt.output, out_format, opt.read, opt.write);
    settings.clean = opt.clean;
    settings.threads = opt.threads;
    if (opt.axis != "auto")
        settings.axis = static_cast<int>(std::find(std::begin(kAxisNames), std::end(kAxisNames), opt.axis) -
                                         std::begin(kAxisNames));
    // A glTF writer holds the whole mesh: without --memory it gets the whole-mesh default.
    settings.writer_shares_budget = !opt.read.memory.empty();
    settings.memory_text = opt.read.memory.empty() ? std::string("256M") : opt.read.memory;
    engine::SortResult result;
    {
        std::optional<Progress> bar;
        result = engine::sort_file(settings, progress ? *progress : bar.emplace("run generation", std::nullopt));
    }
    Warnings warnings = result.warnings;
    note_unused_write_flags(opt.write, out_format, opt.output, warnings);
    print_warnings(warnings);

    if (opt.stats)
        std::fprintf(stderr, "%s\n",
                     sort_stats_line(result.stats, result.axis, seconds_since(t0), result.input_seconds,
                                     result.sort_seconds, peak_rss_bytes())
                         .c_str());
    RunReport report = run_report_of("sort", opt.input, opt.output, result, seconds_since(t0));
    const sort::SortStats& st = result.stats;
    report.details = {{"axis", kAxisNames[result.axis]},
                      {"runs", st.runs},
                      {"merge_passes", st.merge_passes},
                      {"temp_bytes_written", st.temp_bytes_written},
                      {"peak_temp_bytes", st.peak_temp_bytes}};
    return run_report_json(report, warnings);
}

CLI::App* sort_command(CLI::App& app, SortOptions& options) {
    SortOptions* opt = &options;
    CLI::App* cmd = app.add_subcommand(
        "sort", "sort triangles along an axis, out of core, so that decimate can stream them\n" + kInOutText +
                    "\nA stable sort by each triangle's minimum coordinate; the output "
                    "records the axis (docs/sorting.md)");
    cmd->add_option("IN", opt->input, "input mesh ('-' = stdin, needs --axis x, y or z)")->required();
    cmd->add_option("OUT", opt->output, "output mesh ('-' = stdout)")->required();
    cmd->add_option("--axis", opt->axis, "x, y, z or auto: the longest bounding-box axis (default; needs a file)")
        ->type_name("AXIS")
        ->check(CLI::IsMember({"x", "y", "z", "auto"}));
    add_read_flags(cmd, opt->read);
    cmd->get_option("--memory")
        ->description(
            "memory for runs and merge buffers, e.g. 64M, 1G (default 256M)\n"
            "A quarter goes to the reader's and writer's own tables (a glTF writer without --memory gets "
            "half of the memory available, from 256M to 64G); K, M, G, T are binary multiples");
    cmd->get_option("--tmpdir")
        ->group("Options")
        ->description(
            "where sorted runs go (default: the output's directory)\n"
            "When writing to stdout, a pipe or a device: $TMPDIR or /tmp");
    add_write_flags(cmd, opt->write);
    add_clean_flag(cmd, opt->clean);
    add_json_flag(cmd, opt->json);
    add_threads_option(cmd, opt->threads, "read and write on threads of their own");
    cmd->add_flag("--stats", opt->stats, "print runs, merge passes, temporary disk, time and peak RSS on stderr");
    add_drop_flag(cmd, opt->read);
    cmd->get_option("--drop")->group(kMoreOptions);
    cmd->footer(
        "  meshstream sort scan.stl sorted.stl\n"
        "  cat scan.stl | meshstream sort --axis z --to stl - - > sorted.stl");
    return cmd;
}

void add_sort(CLI::App& app) {
    auto opt = std::make_shared<SortOptions>();
    run_when_parsed(sort_command(app, *opt), opt, [](SortOptions& o) { return sort_job(o); });
}

}  // namespace meshstream::tools
