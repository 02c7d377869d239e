// What a library call found that its caller should hear of, as data: counted warnings with a
// stable code (docs/cli.md lists them: the text may change, the code not), and the findings of
// a read loop turned into them. The command prints them ("meshstream: warning: ..."); a library
// user reads all().
#pragma once

#include "io/error.hpp"
#include "io/format.hpp"
#include "io/triangle_input.hpp"

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace meshstream::engine {

class Warnings {
public:
    // A kind of event that can happen many times: told with its count.
    void add(std::string_view code, const std::string& kind, uint64_t count = 1) {
        Entry& e = entries_[kind];
        e.code = code;
        e.count += count;
    }
    // A one-off finding: told as it is.
    void note(std::string_view code, const std::string& text) { entries_.emplace(text, Entry{std::string(code), 0}); }
    // Every warning of `other`, added to these; but those of the codes in `except`, when given.
    void merge(const Warnings& other, const std::set<std::string>* except = nullptr) {
        for (const auto& [text, entry] : other.entries_)
            if (except && except->count(entry.code))
                continue;
            else if (entry.count == 0)
                note(entry.code, text);
            else
                add(entry.code, text, entry.count);
    }
    bool empty() const { return entries_.empty(); }
    // The codes of these warnings.
    std::set<std::string> codes() const {
        std::set<std::string> out;
        for (const auto& [text, entry] : entries_) out.insert(entry.code);
        return out;
    }
    struct Line {
        std::string code, text;
        uint64_t count = 0;  // 0 for a one-off finding
    };
    // In a stable order (by text); text without the count, its settings (io::mention) in the
    // words of `name` (io::setting_words when null).
    std::vector<Line> all(io::SettingNames name = nullptr) const;
    // The same as lines of text: a counted one with its count, "text (12)".
    std::vector<std::string> lines(io::SettingNames name = nullptr) const;

private:
    struct Entry {
        std::string code;
        uint64_t count = 0;
    };
    std::map<std::string, Entry> entries_;
};

// What a finished read loop dropped (io::TriangleInput's policy), and the warnings for it, one
// counted line per kind (`verb`: "skipped" for decimate, "removed (--clean)" for a caller that
// asked for them to go), and a note when the input held no triangles at all.
struct DroppedTriangles {
    uint64_t read = 0, non_finite = 0, degenerate = 0;
};
DroppedTriangles dropped_triangles(const io::TriangleInput& in);
void note_dropped_triangles(const DroppedTriangles& dropped, const std::string& verb, Warnings& warnings);

// Repeats as warnings what the reader noted that changes the data (double coordinates rounded,
// a last line without its end) and the reader's counted warnings (MeshHeader::warnings).
void note_input_changes(const io::MeshHeader& header, const std::string& input_name, Warnings& warnings);

// The warning for channels an output cannot hold: "`dropped` dropped: <format> output carries
// positions only" (or "does not carry them" when it keeps some others, `kept`).
std::string dropped_channels_text(const std::string& dropped, const io::Format& output, const io::Channels& kept);

}  // namespace meshstream::engine
