// Warnings as data: see warnings.hpp.
#include "engine/warnings.hpp"

namespace meshstream::engine {

std::vector<Warnings::Line> Warnings::all(io::SettingNames name) const {
    std::vector<Line> out;
    for (const auto& [text, entry] : entries_) out.push_back({entry.code, io::render(text, name), entry.count});
    return out;
}

std::vector<std::string> Warnings::lines(io::SettingNames name) const {
    std::vector<std::string> out;
    for (const Line& line : all(name))
        out.push_back(line.count == 0 ? line.text : line.text + " (" + std::to_string(line.count) + ")");
    return out;
}

DroppedTriangles dropped_triangles(const io::TriangleInput& in) {
    return {in.count().read, in.non_finite(), in.degenerate()};
}

void note_dropped_triangles(const DroppedTriangles& dropped, const std::string& verb, Warnings& warnings) {
    if (dropped.read == 0) warnings.note("no_triangles", "the input holds no triangles");
    if (dropped.non_finite > 0)
        warnings.add("non_finite_triangles", "triangles with a NaN or infinite coordinate " + verb, dropped.non_finite);
    if (dropped.degenerate > 0)
        warnings.add("degenerate_triangles", "degenerate triangles (two corners at the same position) " + verb,
                     dropped.degenerate);
}

void note_input_changes(const io::MeshHeader& header, const std::string& input_name, Warnings& warnings) {
    for (const auto& [key, text] : header.notes)
        if (key == io::kLastLineNote)
            warnings.note("input_last_line_unterminated", input_name + ": the last line " + text +
                                                              " (a truncated download or pipe?): check its last face");
        else if (key == io::kPrecisionNote && header.coordinate_rounding.value_or(0) > 0)
            warnings.note("input_coordinates_rounded",
                          input_name + ": coordinates are " + text + "; meshstream works in float (32-bit)");
    for (const io::ReaderWarning& w : header.warnings)
        warnings.add("reader_warning", io::describe_warning(input_name, w), w.count);
}

std::string dropped_channels_text(const std::string& dropped, const io::Format& output, const io::Channels& kept) {
    const bool one = dropped.find(',') == std::string::npos;
    return dropped + " dropped: " + std::string(output.name) + " output " +
           (kept.has_attributes() ? std::string(one ? "does not carry it" : "does not carry them")
                                  : std::string("carries positions only"));
}

}  // namespace meshstream::engine
