// `meshstream sort IN OUT`: out-of-core pre-sorting of a triangle stream along one axis, for
// the stream decimator (sort/external_sort.hpp does the sorting; docs/sorting.md explains the
// method and the memory bound). This file chooses the axis, splits --memory between the
// reader/writer and the sorter, drives the progress bar and records the axis in the output.
// With --threads 2 or more, reading runs on a thread of its own during run generation and
// writing during the merge (io/pipeline.hpp), overlapping parsing, inflating, formatting and
// deflating with the sorting on the command's thread; the output is the same.
#include "io/error.hpp"
#include "io/pipeline.hpp"
#include "sort/external_sort.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
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

struct SortOptions {
    std::string input, output;
    std::string axis = "auto";
    bool stats = false;
    bool clean = false;
    bool json = false;
    unsigned threads = every_core();
    ReadFlags read;
    WriteFlags write;
};

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

void run_sort(const SortOptions& opt) {
    const auto t0 = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    const io::Format& out_format = resolve_output_format(opt.output, opt.write);
    // A writer that puts the triangles in an order of its own (Draco's connectivity coder)
    // would lose the sorted order.
    if (out_format.reorders_triangles != nullptr) {
        io::WriteOptions given;
        given.format_options = opt.write.format_options();
        if (const std::string why = out_format.reorders_triangles(given); !why.empty())
            throw UsageError((opt.output == "-" ? std::string("<stdout>") : opt.output) + ": " + why +
                             ", so the sorted order would be lost: write STL, PLY or OBJ (or glTF with --compress "
                             "meshopt or none)");
    }
    // Runs go beside a file output; a pipe or device (/dev/null, /dev/stdout) has no directory
    // of its own for them: /dev is memory.
    const bool output_stream = io::is_stream(opt.output);
    if (!output_stream) {
        // Fail before a long sort, not after it.
        std::string dir = io::parent_dir(opt.output);
        if (::access(dir.c_str(), W_OK) != 0)
            throw io::Error(opt.output, "cannot write here: directory '" + dir + "' does not exist or is not writable");
    }
    // --memory is split: a quarter for the reader's and writer's own tables (indexed formats
    // weld or spill past their share; STL uses none of it), the rest for runs and merge buffers.
    const uint64_t budget = opt.read.options().memory_budget_bytes;
    io::ReadOptions ro = opt.read.options();
    ro.memory_budget_bytes = budget / 4;
    const std::string tmpdir = !opt.read.tmpdir.empty() ? opt.read.tmpdir
                               : !output_stream         ? io::parent_dir(opt.output)
                                                        : std::string();
    ro.tmpdir = tmpdir;

    if (opt.axis == "auto" && !is_regular_file(opt.input))
        throw UsageError((opt.input == "-" ? std::string("<stdin>") : opt.input) +
                         ": --axis auto reads the input twice (bounding box first), which needs a regular file; "
                         "give --axis x, y or z to sort a stream");
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, ro, Command::kSort, opt.clean);
    const io::MeshHeader header = in.header();
    const std::string input_name = in.name();  // the reader is released before the merge
    const RunFile input_file{opt.input, std::string(in.format().name), in.source().gzip()};
    refuse_output_over_inputs(opt.output, out_format, opt.write.options(opt.read, out_format),
                              {input_files(opt.input, header)});
    const int axis = opt.axis == "auto"
                         ? longest_axis(input_bounds(opt.input, opt.read.from, ro))
                         : static_cast<int>(std::find(std::begin(kAxisNames), std::end(kAxisNames), opt.axis) -
                                            std::begin(kAxisNames));
    sort::SorterOptions so;
    so.axis = axis;
    so.tmpdir = tmpdir;
    // Only the channels the output keeps are carried through the runs.
    // --drop's channels are not read: their loss is asked for, so it goes unsaid.
    const io::Channels wanted = ro.channels.of(header.channels);
    so.channels = io::writable_channels(out_format, wanted, opt.write.options(opt.read, out_format));
    const std::string dropped = io::describe_missing(wanted, so.channels);
    const size_t record_bytes = sort::ExternalSorter::record_bytes_for(so.channels);
    // The pipeline's chunks are part of the sorter's share: each at most 1/64 of the budget
    // (counted whether or not threads are used).
    const size_t chunk_capacity =
        std::clamp<size_t>(budget / 64 / (record_bytes + 36), 256, io::TriangleChunk::kDefaultCapacity);
    const uint64_t pipe_bytes = io::kPipelineChunks * chunk_capacity * (record_bytes + 36);
    if (budget - budget / 4 <= pipe_bytes) {
        // The least budget b with b - b/4 > pipe_bytes (the pipe's size is fixed at such small
        // budgets: its chunks are at their minimum), in whole KiB.
        uint64_t least = pipe_bytes * 4 / 3;
        while (least - least / 4 <= pipe_bytes) ++least;
        const uint64_t least_kib = (least + 1023) / 1024;
        throw UsageError(input_name + ": --memory " +
                         (opt.read.memory.empty() ? std::string("256M") : opt.read.memory) +
                         " is too small to sort: give at least " + std::to_string(least_kib) + "K");
    }
    so.memory_budget_bytes = budget - budget / 4 - pipe_bytes;

    Progress progress("run generation", header.triangle_count);
    int shown_pass = 0;
    so.on_merge_progress = [&](int pass, int pass_count, uint64_t merged) {
        if (pass != shown_pass) {
            shown_pass = pass;
            progress.phase("merge pass " + std::to_string(pass) + "/" + std::to_string(pass_count), std::nullopt);
        }
        progress.update(merged);
    };
    sort::ExternalSorter sorter(so);
    {
        // With threads, the input is read, parsed and filtered on a thread of its own; this
        // thread adds the chunks to the runs (and sorts and spills each full run).
        io::TriangleChunk chunk(chunk_capacity, so.channels);
        const std::optional<uint64_t> file_bytes = in.source().stored_size();
        if (opt.threads < 2) {
            while (in.next(chunk)) {
                sorter.add(chunk);
                progress.update(in.count().read, in.source().stored_offset(), file_bytes);
            }
        } else {
            io::ReadAhead reader(in, chunk_capacity, so.channels);
            while (reader.next(chunk)) {
                sorter.add(chunk);
                progress.update(reader.count().read, reader.stored_offset(), file_bytes);
            }
        }
    }
    // What the reader noted by the end of the input (a last line without a line end), before
    // it goes.
    const io::MeshHeader end_header = in.header();
    in.close();  // the reader's buffers and tables are not needed while merging
    const double input_seconds = seconds_since(t0);
    sorter.finish_input();
    const double sort_seconds = seconds_since(t0) - input_seconds;
    const uint64_t total = sorter.triangle_count();

    io::WriteOptions wo = opt.write.options(opt.read, out_format);
    // A glTF writer holds the whole mesh: without --memory it gets the whole-mesh default.
    if (!opt.read.memory.empty() || !(out_format.traits & io::Format::kWholeMesh)) {
        wo.memory_budget_bytes = budget / 4;
        wo.memory_budget_divisor = 4;
    }
    wo.tmpdir = tmpdir;
    wo.triangle_count = total;
    wo.sorted_axis = axis;
    wo.channels = so.channels;
    if (wo.channels.material) wo.materials = end_header.materials;  // with materials added while reading
    io::Output out = io::open_output(opt.output, out_format.name, wo, opt.write.gzip_level);
    const int passes = sorter.stats().merge_passes;
    progress.phase(passes == 0 ? "writing" : "merge " + std::to_string(passes) + "/" + std::to_string(passes), total);
    {
        // With threads, the output is formatted and written on a thread of its own; this thread
        // merges (or gathers) the chunks.
        io::TriangleChunk chunk(chunk_capacity, so.channels);
        uint64_t done = 0;
        if (opt.threads < 2) {
            while (sorter.next(chunk)) {
                out.write(chunk);
                progress.update(done += chunk.size());
            }
        } else {
            io::WriteBehind writer(out, chunk_capacity, so.channels);
            while (sorter.next(chunk)) {
                const size_t n = chunk.size();
                writer.write(chunk);
                progress.update(done += n);
            }
            writer.close();
        }
    }
    out.finish();
    progress.done();
    Warnings warnings;
    note_unused_write_flags(opt.write, *out.format, opt.output, warnings);
    for (const std::string& note : out.writer->notes()) warnings.note("output_note", note);
    if (!dropped.empty()) warnings.note("channels_dropped", dropped_channels_text(dropped, *out.format, so.channels));
    // STL, PLY and OBJ have a place for the axis (a header or a comment); glTF has none.
    if (!out.format->sorted_axis_unrecorded.empty())
        warnings.note("sorted_axis_not_recorded", std::string(opt.output == "-" ? "<stdout>" : opt.output) + ": " +
                                                      std::string(out.format->sorted_axis_unrecorded) +
                                                      ": decimate it with --sorted-axis " + "xyz"[axis] +
                                                      ", or sort to STL, PLY or OBJ, which record it");
    note_dropped_triangles(dropped_triangles(in), "removed (--clean)", warnings);
    note_input_changes(end_header, input_name, warnings);
    print_warnings(warnings);

    if (opt.stats)
        std::fprintf(
            stderr, "%s\n",
            sort_stats_line(sorter.stats(), axis, seconds_since(t0), input_seconds, sort_seconds, peak_rss_bytes())
                .c_str());
    if (opt.json) {
        RunReport report;
        report.command = "sort";
        report.inputs = {input_file};
        report.outputs = {{opt.output, std::string(out.format->name), opt.output != "-" && io::wants_gzip(opt.output)}};
        report.triangles_in = in.count().read;
        report.triangles_out = total;
        report.seconds = seconds_since(t0);
        report.peak_rss_bytes = peak_rss_bytes();
        const sort::SortStats& s = sorter.stats();
        report.details = {{"axis", kAxisNames[axis]},
                          {"runs", s.runs},
                          {"merge_passes", s.merge_passes},
                          {"temp_bytes_written", s.temp_bytes_written},
                          {"peak_temp_bytes", s.peak_temp_bytes}};
        print_json(run_report_json(report, warnings));
    }
}

}  // namespace

void add_sort(CLI::App& app) {
    auto opt = std::make_shared<SortOptions>();
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
    cmd->callback([opt] { run_sort(*opt); });
}

}  // namespace meshstream::tools
