// `meshstream convert IN OUT`: streams triangles between any two registered formats, one chunk
// at a time. With --threads 2 or more the input is read on a thread of its own and the output
// written on another (io/pipeline.hpp), the same bytes out. Memory: one chunk (seven with
// threads: the reader's three, the writer's three and its own) plus whatever the two formats
// need (see docs/formats.md).
#include "io/error.hpp"
#include "io/pipeline.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/run_report.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

namespace meshstream::tools {
namespace {

struct ConvertOptions {
    std::string input, output;
    bool clean = false;
    bool json = false;
    unsigned threads = every_core();
    ReadFlags read;
    WriteFlags write;
};

void run_convert(const ConvertOptions& opt) {
    const auto start = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    const io::Format& out_format = resolve_output_format(opt.output, opt.write);
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, Command::kConvert, opt.clean);
    const io::MeshHeader& header = in.header();
    io::WriteOptions wo = opt.write.options(opt.read, out_format);
    // Every triangle is kept unless --clean: the input's count is then the output's, promised
    // to the writer (binary STL and PLY put it first and need not patch or spool). With
    // --clean it is an upper bound: a writer that puts a count first patches it (files) or
    // spools the body until it knows (stdout, gzip).
    if (!opt.clean) wo.triangle_count = header.triangle_count;
    // PLY states its faces, each at least one triangle.
    wo.expected_triangle_count = header.triangle_count ? header.triangle_count : header.triangle_estimate;
    wo.sorted_axis = header.sorted_axis;
    // --drop's channels are not read: their loss is asked for, so it goes unsaid.
    const io::Channels wanted = opt.read.options().channels.of(header.channels);
    wo.channels = io::writable_channels(out_format, wanted, wo);
    if (wo.channels.material) wo.materials = header.materials;
    const std::string dropped = io::describe_missing(wanted, wo.channels);
    refuse_output_over_inputs(opt.output, out_format, wo, {input_files(opt.input, header)});
    io::Output out = io::open_output(opt.output, out_format.name, wo, opt.write.gzip_level);

    // The chunk carries only what the output keeps: the reader fills no more.
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wo.channels);
    Progress progress("converting", header.triangle_count);
    if (opt.threads < 2) {
        while (in.next(chunk)) {
            out.write(chunk);
            progress.update(in.count().read, in.source());
        }
    } else {
        // Reading (inflating, parsing) on one thread, writing (formatting, welding, encoding,
        // deflating) on another; this thread passes the chunks on and draws the progress.
        const std::optional<uint64_t> file_bytes = in.source().stored_size();
        io::WriteBehind writer(out, chunk.capacity(), chunk.channels());
        io::ReadAhead reader(in, chunk.capacity(), chunk.channels());
        while (true) {
            try {
                if (!reader.next(chunk)) break;
            } catch (...) {
                // Without threads the writes before a read error come first: one of them may
                // fail instead, and that error is the run's.
                writer.close();
                throw;
            }
            writer.write(chunk);
            progress.update(reader.count().read, reader.stored_offset(), file_bytes);
        }
        writer.close();
    }
    // A reader may have added materials while reading (OBJ: names met after the first face).
    if (wo.channels.material) out.writer->update_materials(in.header().materials);
    // Whole-mesh formats encode, and spooled or compressed ones copy, only now: can be most of
    // the run.
    progress.status("converting: finishing " + std::string(out.format->name) + " output (" +
                    human_count(double(in.count().read)) + " triangles read)");
    out.finish();
    progress.done();
    Warnings warnings;
    note_unused_write_flags(opt.write, *out.format, opt.output, warnings);
    for (const std::string& note : out.writer->notes()) warnings.note("output_note", note);
    if (!dropped.empty()) warnings.note("channels_dropped", dropped_channels_text(dropped, *out.format, wo.channels));
    note_dropped_triangles(dropped_triangles(in), "removed (--clean)", warnings);
    note_input_changes(in.header(), in.name(), warnings);
    print_warnings(warnings);
    if (opt.json) {
        RunReport report;
        report.command = "convert";
        report.inputs = {{opt.input, std::string(in.format().name), in.source().gzip()}};
        report.outputs = {{opt.output, std::string(out.format->name), opt.output != "-" && io::wants_gzip(opt.output)}};
        report.triangles_in = in.count().read;
        report.triangles_out = in.count().passed();
        report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        report.peak_rss_bytes = peak_rss_bytes();
        print_json(run_report_json(report, warnings));
    }
}

}  // namespace

void add_convert(CLI::App& app) {
    auto opt = std::make_shared<ConvertOptions>();
    CLI::App* cmd = app.add_subcommand(
        "convert", "any format to any other, every triangle and channel the output can hold kept\n" + kInOutText);
    cmd->add_option("IN", opt->input, "input mesh ('-' = stdin)")->required();
    cmd->add_option("OUT", opt->output, "output mesh ('-' = stdout)")->required();
    add_write_flags(cmd, opt->write);
    cmd->get_option("--compress")->group("Options");
    add_clean_flag(cmd, opt->clean);
    add_drop_flag(cmd, opt->read);
    add_json_flag(cmd, opt->json);
    add_threads_option(cmd, opt->threads, "read and write on threads of their own");
    add_read_flags(cmd, opt->read);
    describe_memory_for_writing(cmd);
    cmd->footer(
        "  meshstream convert scan.ply scan.glb --compress meshopt\n"
        "  meshstream convert scan.stl - --to ply | gzip > scan.ply.gz");
    cmd->callback([opt] { run_convert(*opt); });
}

}  // namespace meshstream::tools
