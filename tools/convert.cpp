// `meshstream convert IN OUT`: streams triangles between any two registered formats, one chunk
// at a time. Memory: one chunk plus whatever the two formats need (see docs/formats.md).
#include "io/error.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/input_filter.hpp"

#include <cstdio>
#include <memory>

namespace meshstream::tools {
namespace {

struct ConvertOptions {
    std::string input, output;
    ReadFlags read;
    WriteFlags write;
};

void run_convert(const ConvertOptions& opt) {
    require_output_format(opt.output, opt.write);
    io::Input in = io::open_input(opt.input, opt.read.from, opt.read.options());
    const io::MeshHeader& header = in.reader->header();
    io::WriteOptions wo = opt.write.options(opt.read);
    // Skipped triangles (input_filter.hpp) make the input's count an upper bound: it is
    // promised to the writer only where nothing can be skipped (--strict). Otherwise a writer
    // that puts a count first patches it (files) or spools the body until it knows (stdout,
    // gzip): a real scan's few degenerate triangles must not fail a pipe at its end.
    if (opt.read.strict) wo.triangle_count = header.triangle_count;
    wo.expected_triangle_count = header.triangle_count;
    wo.sorted_axis = header.sorted_axis;
    const io::Format& out_format = io::output_format(opt.output, opt.write.to);
    wo.channels = io::writable_channels(out_format, header.channels, wo);
    if (wo.channels.material) wo.materials = header.materials;
    const std::string dropped = io::describe_missing(header.channels, wo.channels);
    io::Output out = io::open_output(opt.output, opt.write.to, wo, opt.write.gzip_level);

    // The chunk carries only what the output keeps: the reader fills no more.
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wo.channels);
    uint64_t done = 0;
    Progress progress("converting", header.triangle_count);
    TriangleFilter filter(in.source->name(), opt.read.strict);
    while (in.reader->next(chunk)) {
        done += chunk.size();
        filter.apply(chunk);
        out.write(chunk);
        progress.update(done);
    }
    if (header.triangle_count && done != *header.triangle_count)
        throw io::Error(in.source->name(), "header promises " + std::to_string(*header.triangle_count) +
                                               " triangles, read " + std::to_string(done));
    // Whole-mesh formats encode, and spooled or compressed ones copy, only now: can be most of
    // the run.
    progress.status("converting: finishing " + std::string(out.format->name) + " output (" + human_count(double(done)) +
                    " triangles read)");
    out.finish();
    progress.done();
    Warnings warnings;
    note_unused_write_flags(opt.write, *out.format, opt.output, warnings);
    for (const std::string& note : out.writer->notes()) warnings.note(note);
    if (!dropped.empty()) warnings.note(dropped_channels_text(dropped, *out.format, wo.channels));
    filter.report(warnings);
    note_input_changes(in.reader->header(), in.source->name(), warnings);
    warnings.print();
}

}  // namespace

void add_convert(CLI::App& app) {
    auto opt = std::make_shared<ConvertOptions>();
    CLI::App* cmd = app.add_subcommand(
        "convert", "Convert between formats (detected by magic bytes, then extension; '-' = stdin/stdout).\n"
                   "The output appears under its name only when complete; '.gz' outputs are gzip-compressed.");
    cmd->add_option("input", opt->input, "Input mesh ('-' = stdin)")->required();
    cmd->add_option("output", opt->output, "Output mesh ('-' = stdout, needs --to)")->required();
    add_read_flags(cmd, opt->read);
    add_write_flags(cmd, opt->write);
    cmd->callback([opt] { run_convert(*opt); });
}

}  // namespace meshstream::tools
