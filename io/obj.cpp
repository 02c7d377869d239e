// OBJ reader and writer: line-based parsing from the ByteSource window (lines up to 1 MiB,
// `\` continuations joined in a scratch string), numbers with std::from_chars, as fast_obj
// does with its 64 KiB refill loop; the writer spools through io::Welder.
#include "io/obj.hpp"

#include "io/error.hpp"
#include "io/text_number.hpp"
#include "io/vertex_table.hpp"
#include "io/weld.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace meshstream::io {
namespace {

constexpr std::string_view kSortMarker = "meshstream sorted-axis=";

constexpr const char* kCarriageReturnOnly =
    "carriage return inside a line: lines ending in CR alone (classic Mac OS) are not supported "
    "(tr '\\r' '\\n' converts them)";

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits off the next blank-separated word of `rest`.
std::string_view next_word(std::string_view& rest) {
    size_t i = 0;
    while (i < rest.size() && is_space(rest[i])) ++i;
    size_t j = i;
    while (j < rest.size() && !is_space(rest[j])) ++j;
    std::string_view w = rest.substr(i, j - i);
    rest.remove_prefix(j);
    return w;
}

class ObjReader : public Reader {
public:
    ObjReader(ByteSource& source, const ReadOptions& options)
        : src_(source), options_(options), table_(options.memory_budget_bytes, options.tmpdir, 0) {
        header_.channels.vertex_id = true;
        auto bom = src_.peek(3);  // a UTF-8 byte order mark would hide the first statement
        if (bom.size() == 3 && std::memcmp(bom.data(), "\xEF\xBB\xBF", 3) == 0) src_.consume(3);
        // The leading comments are read now, so a "# meshstream sorted-axis=" line is in the
        // header before the first chunk.
        for (auto w = src_.peek(1); !w.empty() && w[0] == std::byte{'#'}; w = src_.peek(1)) {
            next_line();
            note_comment();
        }
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        for (;;) {
            if (polygon_next_ + 2 < polygon_.size() &&
                !emit_polygon(table_, nullptr, polygon_, polygon_scratch_, &polygon_next_, chunk))
                return true;
            if (chunk.full()) return true;
            if (!next_statement()) return !chunk.empty();
        }
    }

private:
    [[noreturn]] void fail(const std::string& message) const {
        throw Error(src_.name(), line_offset_, line_no_, message);
    }

    // Reads the next logical line into line_; false at the end of the input.
    bool next_line() {
        scratch_.clear();
        bool joined = false;
        for (;;) {
            auto w = src_.window();
            if (w.empty()) {
                if (!joined) {
                    if (unterminated_ && !noted_unterminated_) {
                        header_.notes.emplace_back(kLastLineNote, kLastLineText);
                        noted_unterminated_ = true;
                    }
                    return false;
                }
                line_ = scratch_;
                return true;
            }
            const char* p = reinterpret_cast<const char*>(w.data());
            const void* nl = std::memchr(p, '\n', w.size());
            if (!nl && w.size() < ByteSource::kBufferBytes) {
                w = src_.peek(ByteSource::kBufferBytes);
                p = reinterpret_cast<const char*>(w.data());
                nl = std::memchr(p, '\n', w.size());
            }
            if (!joined) {
                line_offset_ = src_.offset();
                line_no_ = physical_lines_ + 1;
            }
            if (!nl && w.size() >= ByteSource::kBufferBytes) {
                line_no_ = physical_lines_ + 1;
                if (std::memchr(p, '\r', w.size())) fail(kCarriageReturnOnly);
                fail("line longer than 1 MiB");
            }
            size_t len = nl ? static_cast<size_t>(static_cast<const char*>(nl) - p) : w.size();
            std::string_view view(p, len);
            src_.consume(nl ? len + 1 : len);
            ++physical_lines_;
            while (!view.empty() && is_space(view.back())) view.remove_suffix(1);
            unterminated_ = !nl && !view.empty();
            // A CR inside a line: a file whose lines end in CR alone would otherwise read as one
            // line (its first statement only).
            if (std::memchr(view.data(), '\r', view.size())) fail(kCarriageReturnOnly);
            if (!view.empty() && view.back() == '\\') {  // continuation: join with the next line
                view.remove_suffix(1);
                scratch_.append(view);
                scratch_ += ' ';
                joined = true;
                continue;
            }
            if (joined) {
                scratch_.append(view);
                line_ = scratch_;
            } else {
                line_ = view;
            }
            return true;
        }
    }

    // Handles one statement; a face leaves its polygon in polygon_. False at the end.
    bool next_statement() {
        for (;;) {
            if (!next_line()) return false;
            std::string_view rest = line_;
            std::string_view key = next_word(rest);
            if (key.empty()) continue;
            if (key[0] == '#') {
                note_comment();
                continue;
            }
            // A comment may end a statement's line ("f 1 2 3 # top"), as most readers allow.
            if (key == "v" || key == "f") rest = rest.substr(0, rest.find('#'));
            if (key == "v") {
                float xyz[3];
                for (int a = 0; a < 3; ++a) xyz[a] = parse_float(next_word(rest), a);
                // What may follow x y z: w, colour (r g b), or both; numbers only, so that a
                // lost line end ("v 0 0 0 v 1 0 0") is an error instead of a dropped vertex.
                int extra = 0;
                for (std::string_view tok = next_word(rest); !tok.empty(); tok = next_word(rest), ++extra)
                    parse_number(tok, "a number (w or colour) after 'v x y z'");
                if (extra == 2 || extra > 4)
                    fail("'v' with " + std::to_string(3 + extra) + " numbers (x y z, then w and/or r g b)");
                table_.append(xyz, nullptr);
                continue;
            }
            if (key == "f") {
                read_face(rest);
                return true;
            }
            // vt vn vp g o s usemtl mtllib l p and anything else: not geometry we keep. Statement
            // names are ASCII words ("c_interp", "curv2"); anything else is not OBJ text (random
            // bytes under .obj used to read as zero triangles).
            if (!std::all_of(key.begin(), key.end(), [](char c) {
                    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
                }))
                fail("not an OBJ statement: " + quote_token(key));
        }
    }

    void note_comment() {
        size_t at = line_.find(kSortMarker);
        if (at != std::string_view::npos && at + kSortMarker.size() < line_.size()) {
            char axis = line_[at + kSortMarker.size()];
            if (axis >= 'x' && axis <= 'z') header_.sorted_axis = axis - 'x';
        }
    }

    float parse_float(std::string_view tok, int axis) const {
        if (tok.empty()) fail("'v' needs 3 coordinates, found " + std::to_string(axis));
        return parse_number(tok, "a coordinate");
    }

    float parse_number(std::string_view tok, const char* what) const {
        const char* b = tok.data();
        const char* e = b + tok.size();
        if (*b == '+') ++b;
        float v = 0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (ec == std::errc::result_out_of_range) v = std::strtof(std::string(tok).c_str(), nullptr);
        else if (ec != std::errc() || p != e) fail(std::string("expected ") + what + ", found " + quote_token(tok));
        return v;
    }

    void read_face(std::string_view rest) {
        polygon_.clear();
        polygon_next_ = 0;
        const uint64_t defined = table_.size();
        for (;;) {
            std::string_view tok = next_word(rest);
            if (tok.empty()) break;
            // "i", "i/t", "i//n", "i/t/n": the position index comes first.
            std::string_view num = tok.substr(0, tok.find('/'));
            const char* b = num.data();
            const char* e = b + num.size();
            if (b != e && *b == '+') ++b;
            int64_t index = 0;
            auto [p, ec] = std::from_chars(b, e, index);
            if (ec != std::errc() || p != e) fail("expected a vertex index, found " + quote_token(tok));
            if (index == 0) fail("vertex index 0 is invalid (OBJ indices start at 1)");
            int64_t zero_based = index > 0 ? index - 1 : static_cast<int64_t>(defined) + index;
            if (zero_based < 0 || static_cast<uint64_t>(zero_based) >= defined)
                fail("vertex index " + std::to_string(index) + " refers past the " + std::to_string(defined) +
                     " vertices defined so far");
            polygon_.push_back(static_cast<uint64_t>(zero_based));
        }
        if (polygon_.size() < 3 && options_.strict)
            fail("face with " + std::to_string(polygon_.size()) + " vertices (--strict)");
    }

    ByteSource& src_;
    ReadOptions options_;
    VertexTable table_;
    std::string scratch_;
    std::string_view line_;
    uint64_t line_no_ = 0, physical_lines_ = 0, line_offset_ = 0;
    bool unterminated_ = false, noted_unterminated_ = false;  // the last line read had no '\n'
    std::vector<uint64_t> polygon_;
    PolygonScratch polygon_scratch_;
    size_t polygon_next_ = 0;  // next triangle of polygon_ to emit
};

class ObjWriter : public Writer {
public:
    ObjWriter(ByteSink& sink, const WriteOptions& options)
        : sink_(sink), options_(options),
          welder_(options.memory_budget_bytes, options.tmpdir, sink.name(), options.channels) {}

    void write_chunk(const TriangleChunk& chunk) override { welder_.add(chunk); }

    void finish_output() override {
        welder_.finish();
        std::string out = "# generated by meshstream\n";
        if (options_.sorted_axis) out += "# " + std::string(kSortMarker) + char('x' + *options_.sorted_axis) + "\n";
        std::string_view text = options_.comment;
        while (!text.empty()) {
            size_t nl = text.find('\n');
            out += "# " + std::string(text.substr(0, nl)) + "\n";
            if (nl == std::string_view::npos) break;
            text.remove_prefix(nl + 1);
        }
        std::vector<float> xyz(3 * 8192);
        std::vector<std::byte> attributes(welder_.layout().bytes() * 8192);
        while (size_t n = welder_.next_vertices(xyz, attributes)) {
            for (size_t i = 0; i < n; ++i) {
                out += 'v';
                for (int a = 0; a < 3; ++a) {
                    out += ' ';
                    append_number(out, xyz[3 * i + a]);
                }
                out += '\n';
            }
            flush(out);
        }
        std::vector<uint32_t> idx(3 * 8192);
        while (size_t n = welder_.next_indices(idx)) {
            for (size_t t = 0; t + 2 < n; t += 3) {
                out += 'f';
                for (int k = 0; k < 3; ++k) {
                    out += ' ';
                    append_number(out, uint64_t{idx[t + k]} + 1);
                }
                out += '\n';
            }
            flush(out);
        }
        flush(out);
    }

private:
    void flush(std::string& out) {
        sink_.write(out);
        out.clear();
    }

    ByteSink& sink_;
    WriteOptions options_;
    Welder welder_;
};

std::unique_ptr<Reader> open_obj_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<ObjReader>(source, options);
}

std::unique_ptr<Writer> open_obj_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<ObjWriter>(sink, options);
}

}  // namespace

bool guess_obj(std::span<const std::byte> head) {
    if (head.empty()) return false;
    for (std::byte b : head) {
        unsigned char c = static_cast<unsigned char>(b);
        if (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') return false;  // binary
    }
    std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // UTF-8 byte order mark
    static constexpr std::string_view kKeywords[] = {"v", "vt", "vn", "vp", "f", "o", "g", "s", "usemtl", "mtllib", "l", "p"};
    while (!text.empty()) {
        size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
        std::string_view rest = line;
        std::string_view key = next_word(rest);
        if (key.empty() || key[0] == '#') continue;
        for (std::string_view k : kKeywords)
            if (key == k) return true;
        return false;
    }
    return true;  // only comments and blank lines
}

const Format kObjFormat = {
    "obj",
    "obj",
    "Wavefront OBJ (geometry: v and f)",
    nullptr,  // no magic bytes
    &open_obj_reader,
    &open_obj_writer,
    0,
    &guess_obj,
};

}  // namespace meshstream::io
