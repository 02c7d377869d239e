// STL, binary and ASCII: detection, the two readers, the two writers and the format
// descriptors, sharing the format's constants. Binary STL is told apart from ASCII by its size
// (84 + 50·n == size, as OpenMesh's check_stl_type and libigl's is_stl_binary do) or, when the
// size is unknown (stdin, gzip), by bytes that cannot occur in text, never by "solid" alone.
// Both readers parse in place from ByteSource's 1 MiB window (miniply's refill loop); the ASCII
// reader carries the unfinished last line over to the next refill and counts lines for its
// diagnostics. Floats are written with std::to_chars' shortest round-trip form, so
// binary -> ASCII -> binary is bit-exact.
#include "io/stl.hpp"

#include "io/endian.hpp"
#include "io/error.hpp"
#include "io/text_tokens.hpp"
#include "io/triangulate.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>

namespace meshstream::io {
namespace {

constexpr size_t kHeaderBytes = 80;
constexpr size_t kPreambleBytes = 84;  // header + uint32 triangle count
constexpr size_t kFacetBytes = 50;     // normal, 3 vertices (12 floats), uint16 attribute
constexpr size_t kFacetXyzOffset = 12;
constexpr uint64_t kMaxBinaryTriangles = 0xFFFFFFFFu;
constexpr std::string_view kSortMarker = "meshstream sorted-axis=";
constexpr std::string_view kWriterName = "meshstream";

// ---- text classification ----

// Bytes that never occur in an ASCII STL: NUL and the control characters other than
// whitespace. Bytes >= 0x80 are allowed (UTF-8 or Latin-1 solid names).
bool is_binary_byte(std::byte b) {
    auto c = static_cast<unsigned char>(b);
    return c < 0x09 || (c > 0x0d && c < 0x20) || c == 0x7f;
}

bool has_binary_bytes(std::span<const std::byte> head) { return std::any_of(head.begin(), head.end(), is_binary_byte); }

char lower_ascii(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + ('a' - 'A')) : c; }

// Case-insensitive comparison of a token with a lower-case keyword.
bool keyword_is(std::string_view token, std::string_view keyword) {
    if (token.size() != keyword.size()) return false;
    for (size_t i = 0; i < token.size(); ++i)
        if (lower_ascii(token[i]) != keyword[i]) return false;
    return true;
}

bool has_utf8_bom(std::span<const std::byte> head) {
    return head.size() >= 3 && head[0] == std::byte{0xef} && head[1] == std::byte{0xbb} && head[2] == std::byte{0xbf};
}

// True when `head` begins (after an optional UTF-8 BOM and whitespace) with the word "solid",
// in any case, followed by whitespace or the end of the head.
bool starts_with_solid(std::span<const std::byte> head) {
    std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
    if (has_utf8_bom(head)) text.remove_prefix(3);
    while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
    if (text.size() < 5 || !keyword_is(text.substr(0, 5), "solid")) return false;
    return text.size() == 5 || is_blank(text[5]);
}

bool looks_like_ascii_stl(std::span<const std::byte> head) {
    return starts_with_solid(head) && !has_binary_bytes(head);
}

// The printable part of an 80-byte header: up to the first NUL, other unprintable bytes as
// '?', trailing spaces trimmed.
std::string header_text(std::span<const std::byte> header) {
    std::string out;
    for (std::byte b : header) {
        auto c = static_cast<unsigned char>(b);
        if (c == 0) break;
        out += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out;
}

// The axis of a "meshstream sorted-axis=x|y|z" marker in a header or solid name, if any.
std::optional<int> find_sort_marker(std::string_view text) {
    size_t at = text.find(kSortMarker);
    if (at == std::string_view::npos || at + kSortMarker.size() >= text.size()) return std::nullopt;
    char axis = text[at + kSortMarker.size()];
    if (axis < 'x' || axis > 'z') return std::nullopt;
    return axis - 'x';
}

std::string sort_marker(int axis) {
    assert(axis >= 0 && axis <= 2);
    return std::string(kSortMarker) + static_cast<char>('x' + axis);
}

// Facet normal of a triangle (9 floats) in float arithmetic: the normalised cross product of
// its edges, zero for a degenerate triangle.
void facet_normal(const float* v, float* n) {
    float ax = v[3] - v[0], ay = v[4] - v[1], az = v[5] - v[2];
    float bx = v[6] - v[0], by = v[7] - v[1], bz = v[8] - v[2];
    float nx = ay * bz - az * by, ny = az * bx - ax * bz, nz = ax * by - ay * bx;
    float length = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (length > 0.0f && std::isfinite(length)) {
        // + 0.0f turns a -0 into 0: "facet normal 0 -0 1" is correct but looks like a bug.
        n[0] = nx / length + 0.0f;
        n[1] = ny / length + 0.0f;
        n[2] = nz / length + 0.0f;
    } else {
        n[0] = n[1] = n[2] = 0.0f;
    }
}

// ---------------- binary reader ----------------

class BinaryReader : public Reader {
public:
    explicit BinaryReader(ByteSource& source) : source_(source) {
        auto preamble = source_.peek(kPreambleBytes);
        if (preamble.size() < kPreambleBytes)
            throw Error(source_.name(), source_.offset() + preamble.size(), 0,
                        "file ends inside the 84-byte binary STL header (neither binary nor ASCII STL)");
        count_ = load_le<uint32_t>(preamble.data() + kHeaderBytes);
        std::string text = header_text(preamble.first(kHeaderBytes));
        header_.triangle_count = count_;
        end_ = count_;
        header_.variant = "binary";
        header_.sorted_axis = find_sort_marker(text);
        header_.notes.emplace_back("header", text);
        source_.consume(kPreambleBytes);

        if (auto size = source_.size()) {
            // 64-bit arithmetic: 84 + 50·n exceeds 4 GiB from n = 85,899,345 on.
            uint64_t expected = kPreambleBytes + kFacetBytes * count_;
            if (*size != expected) {
                uint64_t body = *size - kPreambleBytes;
                std::string message = "header promises " + std::to_string(count_) + " triangles, file holds " +
                                      std::to_string(body / kFacetBytes);
                if (body % kFacetBytes != 0) message += " and " + std::to_string(body % kFacetBytes) + " stray bytes";
                throw Error(source_.name(), kPreambleBytes, 0, message);
            }
        }
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        const bool plain = chunk.channels() == Channels{};
        while (!chunk.full() && read_ < end_) {
            auto window = source_.window();
            size_t facets =
                std::min<uint64_t>({window.size() / kFacetBytes, chunk.capacity() - chunk.size(), end_ - read_});
            if (facets == 0) {
                // A facet straddles the end of the buffer: peek makes it contiguous.
                window = source_.peek(kFacetBytes);
                if (window.size() < kFacetBytes)
                    throw Error(source_.name(), source_.offset() + window.size(), 0,
                                "file ends inside triangle " + std::to_string(read_ + 1) + " (header promises " +
                                    std::to_string(count_) + " triangles)");
                facets = 1;
            }
            const std::byte* facet = window.data() + kFacetXyzOffset;  // the normal is ignored
            if (plain) {
                float* dst = chunk.xyz_storage() + 9 * chunk.size();
                for (size_t i = 0; i < facets; ++i, facet += kFacetBytes, dst += 9) load_le_array(facet, dst, 9);
                chunk.resize(chunk.size() + facets);
            } else {
                for (size_t i = 0; i < facets; ++i, facet += kFacetBytes) load_le_array(facet, chunk.push_slot(), 9);
            }
            source_.consume(facets * kFacetBytes);
            read_ += facets;
        }
        // Without a known size the count is checked against the end of the stream instead.
        if (read_ == count_ && !end_checked_ && !selected_) {
            end_checked_ = true;
            if (!source_.at_end())
                throw Error(source_.name(), source_.offset(), 0,
                            "header promises " + std::to_string(count_) + " triangles, but more bytes follow");
        }
        return !chunk.empty();
    }

    // The constructor checked the file's size against the count, so the facets are where the
    // count puts them.
    bool select_triangles(uint64_t first, uint64_t end) override {
        if (read_ > 0 || first > end || end > count_ || !source_.size() ||
            !source_.seek(kPreambleBytes + kFacetBytes * first))
            return false;
        read_ = first;
        end_ = end;
        selected_ = true;
        return true;
    }

private:
    ByteSource& source_;
    uint64_t count_ = 0;
    uint64_t read_ = 0;
    uint64_t end_ = 0;  // next() stops before this triangle: count_, or select_triangles()'s end
    bool selected_ = false;
    bool end_checked_ = false;
};

// ---------------- ASCII reader ----------------

class AsciiReader : public Reader {
public:
    AsciiReader(ByteSource& source, bool strict) : source_(source), strict_(strict) {
        header_.variant = "ascii";
        if (has_utf8_bom(source_.peek(3))) source_.consume(3);
        // Read up to the first solid's name so header() can report it before the first chunk.
        parse(nullptr);
        header_.notes.emplace_back("solid", first_name_);
        header_.sorted_axis = find_sort_marker(first_name_);
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        if (!drain(chunk)) return true;
        parse(&chunk);
        return !chunk.empty();
    }

private:
    // What the parser expects next.
    enum class State { kSolid, kFacetOrEnd, kNormal, kLoop, kVertex, kCoordinate, kEndFacet };
    static constexpr size_t kMaxFacetCorners = size_t{1} << 16;

    [[noreturn]] void fail(const std::string& message) const {
        throw Error(source_.name(), Error::kNoOffset, line_, message);
    }
    [[noreturn]] void expected(std::string_view what, std::string_view found) const {
        fail("expected " + std::string(what) + ", found " + quote_token(found));
    }

    // The buffered bytes up to and including the last complete line ("segment"), so no token
    // or line is ever split; the whole rest at the end of the stream. Empty at the end.
    std::string_view segment() {
        auto window = source_.window();
        std::string_view text(reinterpret_cast<const char*>(window.data()), window.size());
        size_t newline = text.rfind('\n');
        while (newline == std::string_view::npos) {
            if (text.size() >= ByteSource::kBufferBytes)
                fail("line longer than " + std::to_string(ByteSource::kBufferBytes >> 20) + " MiB (not an ASCII STL?)");
            size_t had = text.size();
            window = source_.peek(had + 1);
            text = {reinterpret_cast<const char*>(window.data()), window.size()};
            if (text.size() == had) return text;  // end of stream: the last line has no newline
            newline = text.find('\n', had);
            if (newline != std::string_view::npos) newline = text.rfind('\n');
        }
        return text.substr(0, newline + 1);
    }

    // Runs the parser until `chunk` is full or the stream ends; with chunk == null, until the
    // first solid's name has been read. Throws io::Error naming the line.
    void parse(TriangleChunk* chunk) {
        for (;;) {
            std::string_view text = segment();
            if (text.empty()) {
                if (state_ == State::kSolid && solids_ > 0) return;
                // Facets read and all complete, only 'endsolid' missing: read, with a warning
                // (the file may still have been cut between facets). A solid without facets
                // is more likely cut right after its first line: an error.
                if (state_ == State::kFacetOrEnd && facets_in_solid_ > 0 && !strict_) {
                    warn("no 'endsolid' at the end of the file (cut short between facets?)", line_);
                    state_ = State::kSolid;
                    return;
                }
                switch (state_) {
                    case State::kSolid: fail("expected 'solid', found end of file");
                    case State::kFacetOrEnd: fail("expected 'facet' or 'endsolid', found end of file");
                    case State::kNormal: fail("expected 'outer', found end of file");
                    case State::kLoop: fail("expected 'loop', found end of file");
                    case State::kVertex:
                        fail(corners_.size() < 9 ? "expected 'vertex', found end of file"
                                                 : "expected 'endloop', found end of file");
                    case State::kCoordinate: fail("expected a number, found end of file");
                    case State::kEndFacet: fail("expected 'endfacet', found end of file");
                }
            }
            size_t pos = 0;
            bool stop = false;
            while (!stop) {
                while (pos < text.size() && is_blank(text[pos])) {
                    if (text[pos] == '\n') ++line_;
                    ++pos;
                }
                if (pos == text.size()) break;
                size_t end = pos;
                while (end < text.size() && !is_blank(text[end])) ++end;
                std::string_view token = text.substr(pos, end - pos);
                pos = end;
                switch (state_) {
                    case State::kSolid:
                        if (!keyword_is(token, "solid")) expected("'solid'", token);
                        pos = skip_line(text, pos, solids_ == 0 ? &first_name_ : nullptr);
                        ++solids_;
                        facets_in_solid_ = 0;
                        state_ = State::kFacetOrEnd;
                        if (!chunk) stop = true;
                        break;
                    case State::kFacetOrEnd:
                        if (keyword_is(token, "facet")) {
                            state_ = State::kNormal;
                            normal_tokens_ = 0;
                            facet_line_ = line_;
                        } else if (keyword_is(token, "endsolid")) {
                            pos = skip_line(text, pos, nullptr);
                            state_ = State::kSolid;
                        } else {
                            fail("expected 'facet' or 'endsolid', found " + quote_token(token));
                        }
                        break;
                    case State::kNormal:
                        // "normal nx ny nz" is ignored whatever it holds (missing or NaN numbers
                        // occur in the wild); at most those four tokens precede "outer".
                        if (keyword_is(token, "outer")) {
                            state_ = State::kLoop;
                        } else if (++normal_tokens_ > 4) {
                            expected("'outer'", token);
                        }
                        break;
                    case State::kLoop:
                        if (!keyword_is(token, "loop")) expected("'loop'", token);
                        state_ = State::kVertex;
                        corners_.clear();
                        break;
                    case State::kVertex:
                        // Three vertices, then 'endloop'; other counts are read leniently.
                        if (keyword_is(token, "vertex")) {
                            if (corners_.size() == 3 * kMaxFacetCorners)
                                fail("facet with more than " + std::to_string(kMaxFacetCorners) + " vertices");
                            state_ = State::kCoordinate;
                            axis_ = 0;
                            corners_.resize(corners_.size() + 3);
                        } else if (keyword_is(token, "endloop")) {
                            end_loop();
                            state_ = State::kEndFacet;
                        } else {
                            expected(corners_.size() < 9 ? "'vertex'" : "'endloop'", token);
                        }
                        break;
                    case State::kCoordinate:
                        if (!parse_number(token, corners_[corners_.size() - 3 + size_t(axis_)]))
                            expected("a number", token);
                        if (++axis_ == 3) state_ = State::kVertex;
                        break;
                    case State::kEndFacet:
                        if (!keyword_is(token, "endfacet")) expected("'endfacet'", token);
                        state_ = State::kFacetOrEnd;
                        ++facets_in_solid_;
                        assert(chunk);  // the constructor's pass stops after the first 'solid' line
                        if (!drain(*chunk)) stop = true;
                        break;
                }
            }
            source_.consume(pos);
            if (stop) return;
        }
    }

    // Skips to the end of the line (the newline itself is left for the line counter), storing
    // the trimmed rest in *rest when given.
    static size_t skip_line(std::string_view text, size_t pos, std::string* rest) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        if (rest) {
            rest->assign(trim_blanks(text.substr(pos, end - pos)));
        }
        return end;
    }

    // A facet's loop has ended: its triangles go to pending_. Three vertices make one; more
    // are triangulated as PLY and OBJ polygons are (io/triangulate.hpp: the fan when convex);
    // fewer make none. Both are counted warnings, or errors under --strict.
    void end_loop() {
        const size_t n = corners_.size() / 3;
        if (n == 3) {
            pending_.insert(pending_.end(), corners_.begin(), corners_.end());
            return;
        }
        if (strict_)
            throw Error(source_.name(), Error::kNoOffset, facet_line_,
                        "facet with " + std::to_string(n) + " vertices (" + mention(Setting::kStrict) + ")");
        if (n < 3) {
            warn("facets with fewer than 3 vertices skipped", facet_line_);
            return;
        }
        warn("facets with more than 3 vertices split into triangles", facet_line_);
        triangles_.clear();
        triangulate_polygon(corners_, triangulate_scratch_, triangles_);
        for (uint32_t corner : triangles_)
            pending_.insert(pending_.end(), corners_.begin() + 3 * corner, corners_.begin() + 3 * corner + 3);
    }

    // Moves pending triangles into `chunk`; false when it filled up before they ran out.
    bool drain(TriangleChunk& chunk) {
        while (pending_next_ < pending_.size()) {
            if (chunk.full()) return false;
            std::memcpy(chunk.push_slot(), &pending_[pending_next_], 9 * sizeof(float));
            pending_next_ += 9;
        }
        pending_.clear();
        pending_next_ = 0;
        return !chunk.full();
    }

    ByteSource& source_;
    bool strict_;
    State state_ = State::kSolid;
    uint64_t line_ = 1;
    uint64_t facet_line_ = 0;
    uint64_t solids_ = 0;
    uint64_t facets_in_solid_ = 0;
    int normal_tokens_ = 0;
    int axis_ = 0;
    std::vector<float> corners_;  // the current facet's vertices, 3 floats each
    std::vector<float> pending_;  // triangles read but not yet in a chunk, 9 floats each
    size_t pending_next_ = 0;
    std::vector<uint32_t> triangles_;
    TriangulateScratch triangulate_scratch_;
    std::string first_name_;
};

// ---------------- binary writer ----------------

class BinaryWriter : public Writer {
public:
    BinaryWriter(ByteSink& sink, const WriteOptions& options) : sink_(sink), expected_(options.triangle_count) {
        if (expected_ && *expected_ > kMaxBinaryTriangles)
            throw Error(sink_.name(), "binary STL holds at most 4294967295 triangles, " + std::to_string(*expected_) +
                                          " requested (write ASCII STL or another format)");
        std::string text(kWriterName);
        if (options.sorted_axis) text = sort_marker(*options.sorted_axis);
        std::memset(preamble_, ' ', kHeaderBytes);
        std::memcpy(preamble_, text.data(), std::min(text.size(), kHeaderBytes));
        store_le(preamble_ + kHeaderBytes, static_cast<uint32_t>(expected_.value_or(0)));
        // The count goes first when known or patchable; otherwise the body is spooled until
        // finish() knows it (stdout, gzip).
        if (expected_ || sink_.patchable()) {
            header_offset_ = sink_.offset();
            sink_.write(preamble_, kPreambleBytes);
        } else {
            spool_.emplace(options.tmpdir, "meshstream-stl");
        }
        batch_.resize(kBatchFacets * kFacetBytes);
    }

    void write_chunk(const TriangleChunk& chunk) override {
        const uint64_t limit = expected_.value_or(kMaxBinaryTriangles);
        if (written_ + chunk.size() > limit)
            throw Error(sink_.name(), sink_.offset(), 0,
                        expected_
                            ? "more triangles than the " + std::to_string(*expected_) + " announced"
                            : "binary STL holds at most 4294967295 triangles (write ASCII STL or another format)");
        const float* xyz = chunk.xyz().data();
        for (size_t done = 0; done < chunk.size();) {
            size_t facets = std::min(kBatchFacets, chunk.size() - done);
            std::byte* out = batch_.data();
            for (size_t i = 0; i < facets; ++i, xyz += 9, out += kFacetBytes) {
                float normal[3];
                facet_normal(xyz, normal);
                store_le_array(out, normal, 3);
                store_le_array(out + kFacetXyzOffset, xyz, 9);
                out[48] = out[49] = std::byte{0};  // attribute byte count
            }
            if (spool_) {
                spool_->write(batch_.data(), facets * kFacetBytes);
            } else {
                sink_.write(batch_.data(), facets * kFacetBytes);
            }
            done += facets;
        }
        written_ += chunk.size();
    }

    void finish_output() override {
        if (expected_) {
            if (written_ != *expected_)
                throw Error(sink_.name(), "header promises " + std::to_string(*expected_) + " triangles, " +
                                              std::to_string(written_) + " were written");
            return;
        }
        store_le(preamble_ + kHeaderBytes, static_cast<uint32_t>(written_));
        if (!spool_) {
            sink_.patch(header_offset_ + kHeaderBytes, preamble_ + kHeaderBytes, 4);
            return;
        }
        sink_.write(preamble_, kPreambleBytes);
        std::vector<std::byte> block(ByteSink::kBufferBytes);
        const uint64_t total = spool_->size();
        for (uint64_t offset = 0; offset < total;) {
            size_t n = static_cast<size_t>(std::min<uint64_t>(block.size(), total - offset));
            spool_->read_at(offset, block.data(), n);
            sink_.write(block.data(), n);
            offset += n;
        }
        spool_.reset();
    }

private:
    static constexpr size_t kBatchFacets = 4096;

    ByteSink& sink_;
    std::optional<uint64_t> expected_;
    std::optional<TempFile> spool_;
    uint64_t header_offset_ = 0;
    uint64_t written_ = 0;
    std::byte preamble_[kPreambleBytes];
    std::vector<std::byte> batch_;
};

// ---------------- ASCII writer ----------------

class AsciiWriter : public Writer {
public:
    AsciiWriter(ByteSink& sink, const WriteOptions& options) : sink_(sink) {
        name_ = options.sorted_axis ? sort_marker(*options.sorted_axis) : std::string(kWriterName);
        out_.reserve(kFlushBytes + 1024);
        out_ += "solid ";
        out_ += name_;
        out_ += '\n';
    }

    void write_chunk(const TriangleChunk& chunk) override {
        const float* xyz = chunk.xyz().data();
        for (size_t i = 0; i < chunk.size(); ++i, xyz += 9) {
            float normal[3];
            facet_normal(xyz, normal);
            out_ += "facet normal";
            append_floats(normal, 3);
            out_ += "\n  outer loop\n";
            for (int corner = 0; corner < 3; ++corner) {
                out_ += "    vertex";
                append_floats(xyz + 3 * corner, 3);
                out_ += '\n';
            }
            out_ += "  endloop\nendfacet\n";
            if (out_.size() >= kFlushBytes) flush();
        }
    }

    void finish_output() override {
        out_ += "endsolid ";
        out_ += name_;
        out_ += '\n';
        flush();
    }

private:
    static constexpr size_t kFlushBytes = size_t{1} << 20;

    void append_floats(const float* v, int n) {
        char buf[3 * 20];
        char* p = buf;
        for (int i = 0; i < n; ++i) {
            *p++ = ' ';
            // Shortest form that reads back to the same float ("-0" for -0.0).
            p = std::to_chars(p, buf + sizeof buf, v[i]).ptr;
        }
        out_.append(buf, p);
    }

    void flush() {
        sink_.write(out_);
        out_.clear();
    }

    ByteSink& sink_;
    std::string name_;
    std::string out_;
};

// ---------------- descriptors ----------------

bool probe_stl_ascii(std::span<const std::byte> head, std::optional<uint64_t> size) {
    return looks_like_ascii_stl(head) && !probe_stl_binary(head, size);
}

// "stl" reads both encodings: binary when the size says so or the content is not ASCII text.
std::unique_ptr<Reader> open_stl_reader(ByteSource& source, const ReadOptions& options) {
    auto head = source.peek(4096);
    if (probe_stl_binary(head, source.size()) || !looks_like_ascii_stl(head))
        return std::make_unique<BinaryReader>(source);
    return std::make_unique<AsciiReader>(source, options.strict);
}

// "stl-ascii" (--from stl-ascii) insists on ASCII.
std::unique_ptr<Reader> open_stl_ascii_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<AsciiReader>(source, options.strict);
}

std::unique_ptr<Writer> open_stl_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<BinaryWriter>(sink, options);
}

std::unique_ptr<Writer> open_stl_ascii_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<AsciiWriter>(sink, options);
}

}  // namespace

bool probe_stl_binary(std::span<const std::byte> head, std::optional<uint64_t> size) {
    if (head.size() < kPreambleBytes) return false;
    if (size) {
        // Binary STL headers may begin with "solid": trust 84 + 50·n.
        return *size == kPreambleBytes + kFacetBytes * uint64_t{load_le<uint32_t>(head.data() + kHeaderBytes)};
    }
    return !looks_like_ascii_stl(head) && has_binary_bytes(head);
}

const Format kStlFormat = {
    "stl",
    "stl",
    "STL, binary (reads binary and ASCII STL)",
    // Binary STL has no magic: a size that is 84 + 50·n is proof; without a size (a pipe,
    // gzip) "binary bytes, not ASCII STL" is only a guess, tried after the extension (random
    // bytes in a .ply.gz are no STL).
    [](std::span<const std::byte> head, std::optional<uint64_t> size) { return size && probe_stl_binary(head, size); },
    &open_stl_reader,
    &open_stl_writer,
    0,
    [](std::span<const std::byte> head) { return probe_stl_binary(head, std::nullopt); },
};

const Format kStlAsciiFormat = {
    "stl-ascii",
    "",
    "STL, ASCII (written when named, having no extension of its own)",
    &probe_stl_ascii,
    &open_stl_ascii_reader,
    &open_stl_ascii_writer,
};

}  // namespace meshstream::io
