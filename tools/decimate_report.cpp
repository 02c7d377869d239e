// decimate's messages from its statistics: see decimate_report.hpp.
#include "tools/decimate_report.hpp"

#include "decimate/phase_timers.hpp"

#include <cstdio>

namespace meshstream::tools {
namespace {

char axis_name(int axis) { return "xyz"[axis]; }

// The remedy for forced writes, which depends on what is known about the input's order.
std::string forced_write_remedy(const DecimateFacts& f, bool axis_conflict, const std::string& order_command) {
    const decimate::Stats& s = f.stats;
    if (axis_conflict) return "; --sorted-axis overrode the axis the file gives (see below)";
    if (f.used_axis && s.sort_violations == 0 && s.sweep_direction == 0)
        return std::string("; the input is said to be sorted along ") + axis_name(*f.used_axis) +
               ", but its triangles never moved along it by more than three of their lengths, so the sweep that "
               "finalizes hole boundaries never started: check the axis (" +
               order_command + " counts the key descents along each)";
    if (f.used_axis && s.sort_violations == 0)
        return "; the input is sorted, so the buffer is too small for it at this ratio: raise --buffer (" +
               order_command + " estimates the buffer it needs)";
    const std::string how =
        f.sort.kind == SortOutcome::Kind::kCouldNot
            ? "decimate could not sort it first: " + f.sort.why_not + "; run `meshstream sort` on it"
            : "without --sort never decimate sorts it first; or run `meshstream sort` on it";
    return "; either the input is not in streaming order (" + how +
           ") or the buffer is too small for it at this ratio (raise --buffer): " + order_command + " tells which";
}

}  // namespace

void note_decimate_warnings(const DecimateFacts& f, Warnings& warnings) {
    const decimate::Stats& s = f.stats;
    char ratio_text[32];
    std::snprintf(ratio_text, sizeof ratio_text, "%.6g", f.ratio);
    // The command that judges this run's buffer (info assumes the default one).
    const std::string order_command = "`meshstream info --order --ratio " + std::string(ratio_text) +
                                      (f.default_buffer ? "" : " --buffer " + std::to_string(f.buffer)) + "`";
    const bool axis_conflict = f.given_axis && f.file_axis && *f.given_axis != *f.file_axis;
    if (axis_conflict)
        warnings.note("sorted_axis_conflict", std::string("--sorted-axis ") + axis_name(*f.given_axis) +
                                                  " was given, but " + f.input_name + " says it is sorted along " +
                                                  axis_name(*f.file_axis) + ": the sweep used " +
                                                  axis_name(*f.given_axis) + ", as given");
    if (s.forced_writes > 0)
        warnings.note(
            "forced_writes",
            "buffer full of undecimatable triangles: " + std::to_string(s.forced_writes) +
                " triangles force-written at full resolution (" + std::to_string(s.premature_writes) +
                " written before reaching the target resolution; near them a few triangles may come out twice, "
                "back to back)" +
                (s.orphans_evicted > 0
                     ? "; " + std::to_string(s.orphans_evicted) +
                           " of their vertices were evicted from the weld table to make room, so triangles "
                           "read later at those positions are not joined to them (the output has cracks there)"
                     : std::string()) +
                forced_write_remedy(f, axis_conflict, order_command));
    if (f.seam_forced_writes > 0)
        warnings.note("seam_forced_writes",
                      "the seam pass's buffer (" + std::to_string(f.seam_buffer) +
                          " triangles) filled with triangles along seams it could not join yet: " +
                          std::to_string(f.seam_forced_writes) +
                          " triangles force-written at full resolution there; raise --buffer or " +
                          (f.processes > 0 ? "use fewer ranks"
                           : f.parts > 0   ? "use fewer parts"
                                           : "lower --threads"));
    if (s.sort_violations > 0)
        warnings.note(
            "not_sorted_as_stated",
            std::string("the input is not sorted along ") + axis_name(*f.used_axis) + " as stated: " +
                std::to_string(s.sort_violations) + (s.sort_violations == 1 ? " triangle" : " triangles") +
                " reached behind the sweep, which was switched off at the first (boundary finalized before it "
                "may show as cracks); " +
                (axis_conflict ? std::string("leave out --sorted-axis to use the file's own axis")
                               : std::string("run `meshstream sort` on it first")));
    if (s.attribute_values_zeroed > 0)
        warnings.add("attribute_values_zeroed", "non-finite normal, colour, texture or scalar values read as 0",
                     s.attribute_values_zeroed);
    if (s.nonmanifold_edges > 0)
        warnings.add("nonmanifold_edges_frozen",
                     "non-manifold, duplicate or mis-oriented edges frozen and passed through", s.nonmanifold_edges);
    if (s.degenerate_passed > 0)
        warnings.add("degenerate_triangles_passed", "degenerate triangles (repeated corners) passed through",
                     s.degenerate_passed);
    if (s.weld_dropped > 0)
        warnings.add("weld_dropped_triangles", "triangles dropped because --weld merged their corners", s.weld_dropped);
    // Welding that collapses many triangles is coarser than the mesh: it removes surface
    // detail the decimation would have kept.
    if (f.weld_eps > 0 && s.weld_dropped * 100 > s.triangles_in)
        warnings.note("weld_too_coarse",
                      "--weld " + f.weld_text + " welded the corners of " +
                          std::to_string(s.weld_dropped * 100 / s.triangles_in) +
                          " % of the triangles together: it is coarser than the mesh; weld on a smaller size");
    // Triangles that share no corners exactly (cracks from float round-off, a soup written
    // triangle by triangle) leave every edge open: decimation then eats the surface from every
    // crack and still lands on its count. A mesh has far fewer open edges than triangles (a
    // strip one triangle wide about one per triangle); a soup has three. (A few loose triangles
    // are no surface to warn about; an input without triangles: the read loop's note says so.)
    if (s.triangles_in >= 100 && s.boundary_edges * 2 > s.triangles_in * 3)
        warnings.note(
            "unwelded_surface",
            std::to_string(s.boundary_edges) + " edges had no partner, " +
                std::to_string(s.boundary_edges / s.triangles_in) + "." +
                std::to_string(s.boundary_edges * 10 / s.triangles_in % 10) +
                " per triangle: the triangles share few corners exactly (an unwelded surface?), and "
                "decimation removes surface along every open edge; --weld EPS snaps corners to a grid of EPS");
    const std::string missed = "output has " + std::to_string(s.triangles_out) + " triangles instead of the target " +
                               std::to_string(s.target_triangles);
    // Skipped triangles that come late leave --target short: the part read before them was
    // decimated for the larger input the header promised.
    const std::string skipped_late = std::to_string(f.skipped) +
                                     " input triangles were skipped (above), most of them after the part before "
                                     "them had been decimated for the larger input the header promised; `meshstream "
                                     "convert --clean` drops them into a copy that lands on the target";
    if (s.triangles_in > 0 && s.target_triangles > s.triangles_in)
        warnings.note("target_exceeds_input",
                      "the target " + std::to_string(s.target_triangles) + " is more than the " +
                          std::to_string(s.triangles_in) + " usable input triangles: " +
                          (s.collapses == 0 ? std::string("nothing was decimated") : missed + "; " + skipped_late));
    else if (f.target_given && s.triangles_in > 0 && s.triangles_out < s.target_triangles && f.skipped > 0)
        warnings.note("target_missed", missed + " (" + skipped_late + ")");
    else if (s.triangles_in > 0 && s.triangles_out == s.target_triangles + 1)
        warnings.note(
            "target_missed",
            missed +
                " (a collapse removes two triangles, and no boundary edge could be collapsed to remove the odd one)");
    else if (s.triangles_in > 0 && s.triangles_out != s.target_triangles && s.forced_writes > 0)
        warnings.note("target_missed",
                      missed + " (the triangles force-written at full resolution, above, count against it)");
    else if (s.triangles_in > 0 && s.triangles_out != s.target_triangles && s.no_valid_collapse_left)
        warnings.note("target_missed",
                      missed +
                          " (no allowed collapse is left: each would fold a face over or change the topology, "
                          "or move a vertex that must stay, as on a non-manifold edge" +
                          (s.seam_vertices > 0 ? std::string(" or an attribute seam") : std::string()) + ")");
    else if (s.triangles_in > 0 && s.triangles_out > s.target_triangles && s.nonmanifold_edges > 0)
        warnings.note("target_missed",
                      missed + " (the " + std::to_string(s.nonmanifold_edges) +
                          " non-manifold, duplicate or mis-oriented edges above are frozen with their vertices: "
                          "faces wound against their neighbours join none of them)");
    else if (s.triangles_in > 0 && s.triangles_out != s.target_triangles)
        warnings.note("target_missed", missed + " (too little left that could be decimated)");
    else if (s.triangles_in > 0 && s.target_triangles == 0)
        warnings.note("target_rounds_to_zero", "the target rounds to 0 triangles (" + std::to_string(s.triangles_in) +
                                                   " in): the output is empty; give a larger --ratio or --target");
}

std::string count_pass_notice(uint64_t triangles, double seconds, bool for_threads) {
    char line[192];
    std::snprintf(
        line, sizeof line, "counted %llu input triangles in a first pass %s (the input states no count): %.2f s",
        (unsigned long long)triangles, for_threads ? "to cut it into ranges for --threads" : "for --target", seconds);
    return line;
}

std::string sort_notice(const SortOutcome& sort) {
    if (sort.kind != SortOutcome::Kind::kSorted) return {};
    char cost[160];
    std::snprintf(cost, sizeof cost, "%.2f s", sort.attempt_seconds + sort.sort_seconds);
    std::string text = std::string("sorted along ") + axis_name(sort.axis) + " first (";
    if (sort.requested) {
        text += "--sort always";
    } else {
        text += "forced writes began after " + human_count(double(sort.detected_at)) +
                " triangles read, so the input is in no order this buffer holds; `--sort never` decimates it as read";
    }
    text += "): " + std::string(cost);
    if (!sort.requested) {
        char attempt[64];
        std::snprintf(attempt, sizeof attempt, " (%.2f s of it in the first attempt)", sort.attempt_seconds);
        text += attempt;
    }
    return text + ", " +
           (sort.temp_bytes > 0 ? human_bytes(double(sort.temp_bytes)) + " of temporary disk" : "in memory");
}

nlohmann::ordered_json decimate_details_json(const DecimateFacts& f) {
    const decimate::Stats& s = f.stats;
    nlohmann::ordered_json j;
    j["target"] = s.target_triangles;
    j["ratio"] = f.ratio;
    j["buffer"] = s.buffer_capacity;
    j["peak_buffer_fill"] = s.peak_buffer_triangles;
    j["collapses"] = s.collapses;
    j["seam_vertices"] = s.seam_vertices;
    j["forced_writes"] = s.forced_writes;
    j["skipped_triangles"] = f.skipped;
    j["sorted_axis"] =
        f.used_axis ? nlohmann::ordered_json(std::string(1, axis_name(*f.used_axis))) : nlohmann::ordered_json(nullptr);
    if (f.weld_eps > 0) j["weld"] = {{"size", f.weld_eps}, {"vertices_merged", s.vertices_merged}};
    if (f.count_pass_seconds) j["count_pass_seconds"] = *f.count_pass_seconds;
    j["threads"] = f.threads;
    if (f.processes > 0) j["processes"] = f.processes;
    if (f.parts > 0) j["parts"] = f.parts;
    if (f.sort.kind == SortOutcome::Kind::kSorted)
        j["sorted_first"] = {{"axis", std::string(1, axis_name(f.sort.axis))},
                             {"requested", f.sort.requested},
                             {"seconds", f.sort.attempt_seconds + f.sort.sort_seconds},
                             {"temp_bytes", f.sort.temp_bytes}};
    return j;
}

void print_decimate_summary(const DecimateFacts& f, const std::string& output, double seconds) {
    const decimate::Stats& s = f.stats;
    std::fprintf(stderr, "decimated %s -> %s\n", f.input_name.c_str(), output.c_str());
    if (const std::string notice = sort_notice(f.sort); !notice.empty()) std::fprintf(stderr, "  %s\n", notice.c_str());
    if (f.count_pass_seconds)
        std::fprintf(stderr, "  %s\n",
                     count_pass_notice(f.stats.triangles_in, *f.count_pass_seconds, f.count_pass_for_threads).c_str());
    std::fprintf(stderr, "  triangles in %llu, out %llu (target %llu, ratio %.6g)\n",
                 (unsigned long long)s.triangles_in, (unsigned long long)s.triangles_out,
                 (unsigned long long)s.target_triangles, f.ratio);
    std::fprintf(stderr, "  time %.3f s, %s input triangles/s, peak RSS %s\n", seconds,
                 human_count(seconds > 0 ? double(s.triangles_in) / seconds : 0).c_str(),
                 human_bytes(double(peak_rss_bytes())).c_str());
    std::fprintf(stderr, "  buffer %zu triangles, peak fill %zu (%.1f %%), collapses %llu, forced writes %llu\n",
                 s.buffer_capacity, s.peak_buffer_triangles,
                 100.0 * double(s.peak_buffer_triangles) / double(s.buffer_capacity), (unsigned long long)s.collapses,
                 (unsigned long long)s.forced_writes);
    if (f.threads > 1)
        std::fprintf(stderr,
                     "  threads %u: %u ranges decimated at once, seams joined by a pass through %zu triangles\n",
                     f.threads, f.threads, f.seam_buffer);
    if (f.processes > 1)
        std::fprintf(stderr,
                     "  processes %u: %u ranges decimated at once by MPI ranks, seams joined by a pass through %zu "
                     "triangles\n",
                     f.processes, f.processes, f.seam_buffer);
    if (f.parts > 1)
        std::fprintf(stderr,
                     "  parts %u: ranges 1 to %u read from part files, range %u decimated here, seams joined by a "
                     "pass through %zu triangles\n",
                     f.parts, f.parts - 1, f.parts, f.seam_buffer);
    if (f.weld_eps > 0)
        std::fprintf(stderr, "  weld %.6g: %llu vertices merged\n", f.weld_eps, (unsigned long long)s.vertices_merged);
    if (f.used_axis)
        std::fprintf(stderr, "  sorted along %c (%s): %llu hole-boundary vertices finalized by the sweep\n",
                     axis_name(*f.used_axis),
                     s.sweep_direction > 0   ? "ascending"
                     : s.sweep_direction < 0 ? "descending"
                                             : "direction not seen",
                     (unsigned long long)s.vertices_finalized_by_sweep);
    decimate::print_phase_report(stderr);  // only in builds with MESHSTREAM_PHASE_TIMERS
}

}  // namespace meshstream::tools
