// `meshstream compare A B`: Metro-style surface error between two meshes (compare/metro.hpp),
// and with --attributes their colour and normal error, as text or --json. Holds the smaller
// mesh in memory and streams the other one twice.
#include "compare/metro.hpp"
#include "io/error.hpp"
#include "tools/cli_checks.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/jobs.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

namespace meshstream::tools {
namespace {

using compare::AttributeErrors;
using compare::AttributeStats;
using compare::compare_meshes;
using compare::CompareOptions;
using compare::CompareResult;
using compare::DistanceStats;
using compare::file_source;
using compare::MeshSource;
using compare::MeshSummary;
using compare::NoSharedAttributes;

// The held mesh's bytes per sample at the peak, while its BVH is built, for refusing a
// --samples past memory: 626 MB for 10 M samples against a 10 k-triangle mesh. --attributes
// adds 24 for colours and 24 for normals (a sample's own value and the one at its nearest
// point, 3 floats each): 1.06 GB against 571 MB on another such mesh with both.
constexpr int kSampleBytes = 60;
constexpr int kSampleBytesWithAttributes = 108;

nlohmann::ordered_json mesh_json(const MeshSummary& m) {
    nlohmann::ordered_json j;
    j["file"] = m.name;
    j["triangles"] = m.triangles;
    if (m.non_finite_triangles) j["non_finite_triangles"] = m.non_finite_triangles;
    j["area"] = m.area;
    j["bbox_min"] = {m.bounds.min[0], m.bounds.min[1], m.bounds.min[2]};
    j["bbox_max"] = {m.bounds.max[0], m.bounds.max[1], m.bounds.max[2]};
    j["diagonal"] = m.diagonal();
    j["edges"] = m.edges.edges;
    j["boundary_edges"] = m.edges.boundary_edges;
    j["non_manifold_edges"] = m.edges.non_manifold_edges;
    j["held_in_memory"] = m.in_memory;
    return j;
}

// A direction without samples measured nothing: its figures are null, not 0; so are
// percentages of a zero diagonal.
nlohmann::ordered_json stats_json(const DistanceStats& s, double diagonal) {
    auto value = [&](double v) { return s.samples > 0 ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
    auto pct = [&](double v) { return diagonal > 0 ? value(100.0 * v / diagonal) : nlohmann::ordered_json(); };
    nlohmann::ordered_json j;
    j["samples"] = s.samples;
    j["max"] = value(s.max);
    j["mean"] = value(s.mean);
    j["rms"] = value(s.rms);
    j["max_pct"] = pct(s.max);
    j["mean_pct"] = pct(s.mean);
    j["rms_pct"] = pct(s.rms);
    return j;
}

// An attribute's errors one way (or both, symmetric): null figures without samples, as above.
nlohmann::ordered_json attribute_json(const AttributeStats& s) {
    auto value = [&](double v) { return s.samples > 0 ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
    nlohmann::ordered_json j;
    j["max"] = value(s.max);
    j["rms"] = value(s.rms);
    j["samples"] = s.samples;
    j["skipped"] = s.skipped;
    return j;
}

// Adds --attributes' "color" and "normal_degrees" to a direction's object: null for a channel
// the two meshes do not share.
void add_attribute_json(nlohmann::ordered_json& j, const AttributeErrors& e, const AttributeStats& color,
                        const AttributeStats& normal) {
    j["color"] = e.color ? attribute_json(color) : nlohmann::ordered_json();
    j["normal_degrees"] = e.normal ? attribute_json(normal) : nlohmann::ordered_json();
}

// compare measures each file as it is; with --strict a NaN/inf or degenerate triangle is an
// error instead, as in the other commands (the read loop refuses it), and so is a header
// whose promised count the file breaks.
class StrictReader final : public io::Reader {
public:
    StrictReader(std::unique_ptr<io::Reader> in, const std::string& name)
        : in_(std::move(in), name, io::BadTriangles::kRefuse) {
        header_ = in_.header();
    }
    bool next(io::TriangleChunk& chunk) override { return in_.next(chunk); }

private:
    io::TriangleInput in_;
};

MeshSource source(const std::string& path, const ReadFlags& flags, bool attributes) {
    io::ReadOptions options = flags.options();
    // Readers that keep vertices (PLY) then store only the channels compare reads.
    options.channels = io::ChannelKinds::none();
    options.channels.colors = options.channels.normals = attributes;
    MeshSource s = file_source(path, flags.from, options);
    if (flags.strict)
        s.open = [open = s.open, path] {
            return std::make_unique<StrictReader>(open(), path == "-" ? "<stdin>" : path);
        };
    return s;
}

// --attributes' text: per channel a heading and the three rows, or why it is not measured.
void print_attributes(const CompareResult& r) {
    const AttributeErrors& e = *r.attributes;
    auto row = [](const char* label, const AttributeStats& s, bool symmetric) {
        if (s.samples == 0) {
            if (s.skipped)
                std::printf("%-10s not measured: all %llu samples skipped\n", label, (unsigned long long)s.skipped);
            else
                std::printf("%-10s no samples: not measured\n", label);
            return;
        }
        // The figures are padded to line up with what follows them, if anything does.
        const bool more = !symmetric || s.skipped;
        std::printf(more ? "%-10s max %-12.6g rms %-12.6g" : "%-10s max %-12.6g rms %.6g", label, s.max, s.rms);
        if (!symmetric) std::printf("  %llu samples", (unsigned long long)s.samples);
        if (s.skipped) std::printf("%s%llu skipped", symmetric ? "  " : ", ", (unsigned long long)s.skipped);
        std::printf("\n");
    };
    // Why a channel is not measured (the other one is: else compare refuses --attributes).
    auto lacking = [](bool a, bool b, const char* what) {
        return std::string(!a && !b ? "neither A nor B has " : !a ? "A has no " : "B has no ") + what;
    };
    if (e.color) {
        std::printf("colour error (distance of RGB, each 0..1; alpha ignored):\n");
        row("A -> B", e.color_a_to_b, false);
        row("B -> A", e.color_b_to_a, false);
        row("symmetric", e.color_symmetric(), true);
    } else {
        std::printf("colour error: not measured (%s)\n",
                    lacking(r.a.channels.color.has_value(), r.b.channels.color.has_value(), "colours").c_str());
    }
    if (e.normal) {
        std::printf("normal error (degrees between the normals; skipped: a zero-length or non-finite normal):\n");
        row("A -> B", e.normal_a_to_b, false);
        row("B -> A", e.normal_b_to_a, false);
        row("symmetric", e.normal_symmetric(), true);
    } else {
        std::printf("normal error: not measured (%s)\n",
                    lacking(r.a.channels.normal, r.b.channels.normal, "normals").c_str());
    }
}

}  // namespace

nlohmann::ordered_json compare_job(const CompareCliOptions& opt, engine::ProgressSink* progress) {
    if (is_stream(opt.a) && is_stream(opt.b))
        throw UsageError("compare cannot read both A and B from stdin or pipes: one of them is read twice");
    // What compare prints must not land in a file it reads (`compare a.stl b.stl >> a.stl`).
    refuse_output_over_inputs("-", {}, {{opt.a, {}}, {opt.b, {}}});
    // The held mesh keeps every sample (kSampleBytes): a count past memory would only fail
    // after minutes of work, as a bare "out of memory".
    const int bytes_each = opt.attributes ? kSampleBytesWithAttributes : kSampleBytes;
    const double sample_bytes = bytes_each * double(opt.samples.value_or(0)), ram = physical_memory_bytes();
    if (ram > 0 && sample_bytes > ram)
        throw UsageError("--samples " + std::to_string(*opt.samples) + ": the held mesh's samples alone take about " +
                         human_bytes(sample_bytes) + " (" + std::to_string(bytes_each) + " bytes each" +
                         (opt.attributes ? " with --attributes" : "") + "), more than this machine's memory (" +
                         human_bytes(ram) + ")");
    io::ReadOptions read = opt.read.options();
    CompareOptions co;
    co.samples = opt.samples;
    co.seed = opt.seed;
    co.memory_budget_bytes = read.memory_budget_bytes;
    co.tmpdir = read.tmpdir;
    co.attributes = opt.attributes;
    std::optional<Progress> bar;
    if (!progress) bar.emplace("comparing", std::nullopt);
    engine::ProgressSink& sink = progress ? *progress : *bar;
    std::string last_phase;
    co.progress = [&](std::string_view phase, uint64_t done, std::optional<uint64_t> total) {
        if (phase != last_phase) {
            last_phase = std::string(phase);
            sink.phase(last_phase, total);
        }
        sink.update(done);
        engine::throw_if_cancelled(sink);
    };
    CompareResult r;
    try {
        r = compare_meshes(source(opt.a, opt.read, opt.attributes), source(opt.b, opt.read, opt.attributes), co);
    } catch (const NoSharedAttributes& e) {
        throw UsageError(std::string("--attributes: ") + e.describe(flag_name));
    }
    if (bar) bar->done();

    double diag = r.diagonal;
    // A mesh of zero area (degenerate triangles only), or --samples too small for it, gets no
    // samples: that direction is unmeasured, and the symmetric figures are the other one's.
    Warnings warnings;
    const bool none = r.a_to_b.samples == 0 && r.b_to_a.samples == 0;
    auto unsampled = [&](const MeshSummary& from, const char* direction) {
        warnings.note("no_samples",
                      std::string("no samples on ") + from.name + " (" +
                          (from.area > 0 ? "too few asked for: raise --samples" : "its triangles have no area") +
                          "): " + direction + " is not measured" +
                          (none ? std::string() : ", and the symmetric figures are the other direction's alone"));
    };
    if (r.a_to_b.samples == 0) unsampled(r.a, "A -> B");
    if (r.b_to_a.samples == 0) unsampled(r.b, "B -> A");
    print_warnings(warnings);
    if (opt.json) {
        nlohmann::ordered_json j;
        j["a"] = mesh_json(r.a);
        j["b"] = mesh_json(r.b);
        j["seed"] = opt.seed;
        j["a_to_b"] = stats_json(r.a_to_b, diag);
        j["b_to_a"] = stats_json(r.b_to_a, diag);
        DistanceStats sym;
        sym.samples = r.a_to_b.samples + r.b_to_a.samples;
        sym.max = r.hausdorff();
        sym.mean = r.mean();
        sym.rms = r.rms();
        nlohmann::ordered_json s = stats_json(sym, diag);
        s.erase("samples");
        if (r.attributes) {
            const AttributeErrors& e = *r.attributes;
            add_attribute_json(j["a_to_b"], e, e.color_a_to_b, e.normal_a_to_b);
            add_attribute_json(j["b_to_a"], e, e.color_b_to_a, e.normal_b_to_a);
            add_attribute_json(s, e, e.color_symmetric(), e.normal_symmetric());
        }
        j["symmetric"] = s;
        j["diagonal"] = diag;
        return j;
    }
    auto mesh_line = [](const char* label, const MeshSummary& m) {
        std::printf("%s %s\n", label, m.name.c_str());
        std::printf("   triangles %llu, edges %llu, boundary edges %llu, non-manifold edges %llu, area %.6g%s\n",
                    (unsigned long long)m.triangles, (unsigned long long)m.edges.edges,
                    (unsigned long long)m.edges.boundary_edges, (unsigned long long)m.edges.non_manifold_edges, m.area,
                    m.in_memory ? " (held in memory)" : " (streamed)");
        if (m.non_finite_triangles)
            std::printf("   %llu triangles with non-finite coordinates skipped\n",
                        (unsigned long long)m.non_finite_triangles);
    };
    mesh_line("A:", r.a);
    mesh_line("B:", r.b);
    std::printf("A bbox diagonal: %.9g (percentages below are of it)\n", diag);
    auto pct = [&](double v) {
        char text[40];
        // Past a million % (a far outlier in B against a tiny A) fixed notation would run on.
        if (diag > 0)
            std::snprintf(text, sizeof text, 100.0 * v / diag < 1e6 ? "%8.5f%%" : "%.4g%%", 100.0 * v / diag);
        else
            std::snprintf(text, sizeof text, "%9s", "n/a");  // a point: no size to relate to
        return std::string(text);
    };
    auto row = [&](const char* label, double max, double mean, double rms, std::optional<uint64_t> samples) {
        if (samples == 0u) {
            std::printf("%-10s no samples: not measured\n", label);
            return;
        }
        std::printf("%-10s max %-12.6g (%s)  mean %-12.6g (%s)  rms %-12.6g (%s)", label, max, pct(max).c_str(), mean,
                    pct(mean).c_str(), rms, pct(rms).c_str());
        if (samples) std::printf("  %llu samples", (unsigned long long)*samples);
        std::printf("\n");
    };
    row("A -> B", r.a_to_b.max, r.a_to_b.mean, r.a_to_b.rms, r.a_to_b.samples);
    row("B -> A", r.b_to_a.max, r.b_to_a.mean, r.b_to_a.rms, r.b_to_a.samples);
    if (none)
        row("symmetric", 0, 0, 0, 0);
    else
        row("symmetric", r.hausdorff(), r.mean(), r.rms(), std::nullopt);
    if (r.attributes) print_attributes(r);
    return nullptr;
}

CLI::App* compare_command(CLI::App& app, CompareCliOptions& options) {
    CompareCliOptions* opt = &options;
    CLI::App* cmd = app.add_subcommand(
        "compare",
        "Hausdorff, mean and RMS surface error between two meshes (Metro)\n"
        "A, B: mesh files ('-' for stdin, one of them at most), e.g. the original and its decimation.\n"
        "Area-weighted samples on each surface, their distance to the other one, both ways; and each mesh's\n"
        "boundary and non-manifold edges. The smaller mesh is held in memory, about 60 bytes a triangle and\n"
        "60 a sample; the other one is streamed twice, so it may be far larger than memory (docs/cli.md).\n"
        "--attributes adds colour and normal error: each sample's value against the other surface's at its\n"
        "nearest point (RMS, max), for the channels both meshes have; each adds 24 bytes a held sample.");
    cmd->add_option("A", opt->a, "mesh A (the reference, e.g. the original; '-' = stdin)")->required();
    cmd->add_option("B", opt->b, "mesh B (e.g. the decimated mesh)")->required();
    cmd->add_option("--samples", opt->samples,
                    "samples per direction (default: 10 x the sampled mesh's triangles, within 1e6..1e7)")
        ->type_name("N")
        ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 32));
    cmd->add_option("--seed", opt->seed, "random seed of the sampling (default 1): same seed, same figures")
        ->type_name("N")
        ->check(whole_number(0, "a whole number"));
    cmd->add_flag("--attributes", opt->attributes,
                  "also measure colour and normal error at each sample (the channels both meshes have)");
    cmd->add_flag("--json", opt->json, "print JSON instead of text");
    add_read_flags(cmd, opt->read);
    cmd->get_option("--memory")
        ->description(
            "budget for counting the streamed mesh's edges (default 256M)\n"
            "Spills to --tmpdir past it; K, M, G, T are binary multiples");
    strict_reports_bad_triangles(cmd);
    cmd->footer(
        "  meshstream compare scan.ply scan_1.glb\n  meshstream compare --attributes coloured.ply coloured_10.ply");
    return cmd;
}

void add_compare(CLI::App& app) {
    auto opt = std::make_shared<CompareCliOptions>();
    run_when_parsed(
        compare_command(app, *opt), opt, [](CompareCliOptions& o) { return compare_job(o); }, 2);
}

}  // namespace meshstream::tools
