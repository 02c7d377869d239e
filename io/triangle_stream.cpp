// meshstream's triangle stream (see triangle_stream.hpp and docs/formats.md): the reader, the
// writer and the descriptor, sharing the record layout. A record is the triangle's positions
// followed by every channel the header names, each in the chunk's own travelling type (floats,
// doubles, uint64 ids, a uint32 material), so a chunk goes through a pipe bit for bit.
#include "io/triangle_stream.hpp"

#include "io/endian.hpp"
#include "io/error.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace meshstream::io {
namespace {

constexpr std::byte kMagic[8] = {std::byte{0x89}, std::byte{'M'},  std::byte{'S'},  std::byte{'H'},
                                 std::byte{0x0D}, std::byte{0x0A}, std::byte{0x1A}, std::byte{0x0A}};
constexpr std::byte kEndTag[4] = {std::byte{'M'}, std::byte{'S'}, std::byte{'H'}, std::byte{'E'}};
constexpr uint32_t kVersion = 1;
constexpr uint64_t kUnknownCount = ~uint64_t{0};
constexpr uint32_t kMaxChunkTriangles = uint32_t{1} << 24;  // larger: a corrupt stream
constexpr size_t kPreambleBytes = 8 + 4 + 8;                // magic, version, body bytes
constexpr uint8_t kNoAxis = 0xFF;
// Named scalar channels of each kind a stream may declare: each costs every chunk a slot per
// triangle, so a corrupt count must not allocate gigabytes (a PLY rarely has ten).
constexpr uint32_t kMaxScalarChannels = 64;
// Corner flags of the header body.
constexpr uint8_t kNormalFlag = 1, kColorFlag = 2, kVertexIdFlag = 4;

// Scalar type codes on the wire (fixed here, independent of the enum's order).
uint8_t type_code(ScalarType type) {
    switch (type) {
        case ScalarType::kInt8: return 0;
        case ScalarType::kUInt8: return 1;
        case ScalarType::kInt16: return 2;
        case ScalarType::kUInt16: return 3;
        case ScalarType::kInt32: return 4;
        case ScalarType::kUInt32: return 5;
        case ScalarType::kFloat32: return 6;
        case ScalarType::kFloat64: return 7;
    }
    return 6;
}

std::optional<ScalarType> type_from_code(uint8_t code) {
    constexpr ScalarType kTypes[] = {ScalarType::kInt8,    ScalarType::kUInt8,  ScalarType::kInt16,
                                     ScalarType::kUInt16,  ScalarType::kInt32,  ScalarType::kUInt32,
                                     ScalarType::kFloat32, ScalarType::kFloat64};
    if (code >= std::size(kTypes)) return std::nullopt;
    return kTypes[code];
}

// Bytes of one triangle record for `c`.
size_t record_bytes(const Channels& c) {
    return 9 * sizeof(float) + (c.normal ? 9 * sizeof(float) : 0) + (c.color ? 12 * sizeof(float) : 0) +
           size_t(c.uv_sets) * 6 * sizeof(float) + c.vertex_scalars.size() * 3 * sizeof(double) +
           (c.vertex_id ? 3 * sizeof(uint64_t) : 0) + (c.material ? sizeof(uint32_t) : 0) +
           c.face_scalars.size() * sizeof(double);
}

// ---- header body ----

void put_string(std::vector<std::byte>& out, const std::string& s) {
    append_le(out, static_cast<uint32_t>(s.size()));
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    out.insert(out.end(), p, p + s.size());
}

void put_scalars(std::vector<std::byte>& out, const std::vector<ScalarChannel>& scalars) {
    append_le(out, static_cast<uint32_t>(scalars.size()));
    for (const ScalarChannel& s : scalars) {
        append_le(out, type_code(s.type));
        put_string(out, s.name);
    }
}

std::vector<std::byte> header_body(const WriteOptions& o) {
    const Channels& c = o.channels;
    std::vector<std::byte> body;
    append_le(body, o.triangle_count.value_or(kUnknownCount));
    append_le(body, static_cast<uint8_t>(o.sorted_axis ? *o.sorted_axis : kNoAxis));
    append_le(body, static_cast<uint8_t>((c.normal ? kNormalFlag : 0) | (c.color ? kColorFlag : 0) |
                                         (c.vertex_id ? kVertexIdFlag : 0)));
    append_le(body, static_cast<uint8_t>(c.color ? type_code(c.color->type) : 0));
    append_le(body, static_cast<uint8_t>(c.color && c.color->alpha ? 1 : 0));
    append_le(body, static_cast<uint8_t>(c.uv_sets));
    append_le(body, static_cast<uint8_t>(c.material ? 1 : 0));
    append_le(body, uint16_t{0});
    put_scalars(body, c.vertex_scalars);
    put_scalars(body, c.face_scalars);
    const std::vector<Material> none;
    const std::vector<Material>& materials = c.material ? o.materials : none;
    append_le(body, static_cast<uint32_t>(materials.size()));
    for (const Material& m : materials) {
        put_string(body, m.name);
        for (float v : m.base_color) append_le(body, v);
        append_le(body, static_cast<uint8_t>(m.texture ? 1 : 0));
        if (m.texture) {
            put_string(body, m.texture->uri);
            put_string(body, m.texture->mime_type);
            append_le(body, static_cast<uint64_t>(m.texture->bytes.size()));
            body.insert(body.end(), m.texture->bytes.begin(), m.texture->bytes.end());
        }
    }
    return body;
}

// Reads the header body, each field checked against the bytes left; errors name the byte.
class BodyCursor {
public:
    BodyCursor(const ByteSource& source, const std::vector<std::byte>& body, uint64_t base)
        : source_(source), body_(body), base_(base) {}
    template <class T>
    T get(const char* what) {
        field_ = pos_;
        need(sizeof(T), what);
        T v = load_le<T>(body_.data() + pos_);
        pos_ += sizeof(T);
        return v;
    }
    std::string string(const char* what) {
        const uint32_t n = get<uint32_t>(what);
        field_ = pos_;
        need(n, what);
        std::string s(reinterpret_cast<const char*>(body_.data() + pos_), n);
        pos_ += n;
        return s;
    }
    std::vector<std::byte> bytes(uint64_t n, const char* what) {
        field_ = pos_;
        need(n, what);
        std::vector<std::byte> b(body_.begin() + static_cast<std::ptrdiff_t>(pos_),
                                 body_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
        pos_ += n;
        return b;
    }
    // Throws io::Error at the byte where the last field read began.
    [[noreturn]] void fail(const std::string& message) const {
        throw Error(source_.name(), base_ + field_, 0, message);
    }
    bool done() const { return pos_ == body_.size(); }

private:
    void need(uint64_t n, const char* what) {
        if (n > body_.size() - pos_)
            fail(std::string("header ends inside ") + what + " (the header says it has " +
                 std::to_string(body_.size()) + " bytes)");
    }
    const ByteSource& source_;
    const std::vector<std::byte>& body_;
    uint64_t base_;
    size_t pos_ = 0;
    size_t field_ = 0;  // where the last field read began
};

// The scalar channels of one kind ("vertex scalar", "face scalar"): a count, then each one's
// type and name.
std::vector<ScalarChannel> get_scalars(BodyCursor& in, const std::string& kind) {
    const std::string what = "the " + kind + " channels";
    const uint32_t n = in.get<uint32_t>(what.c_str());
    if (n > kMaxScalarChannels)
        in.fail(std::to_string(n) + " " + kind + " channels (at most " + std::to_string(kMaxScalarChannels) + ")");
    std::vector<ScalarChannel> scalars;
    for (uint32_t i = 0; i < n; ++i) {
        const uint8_t code = in.get<uint8_t>(what.c_str());
        const std::optional<ScalarType> type = type_from_code(code);
        if (!type) in.fail(kind + " channel " + std::to_string(i) + ": unknown scalar type " + std::to_string(code));
        scalars.push_back({in.string(what.c_str()), *type});
    }
    return scalars;
}

// ---- reader ----

class StreamReader final : public Reader {
public:
    StreamReader(ByteSource& source, const ReadOptions& options) : source_(source) {
        std::byte preamble[kPreambleBytes];
        if (source_.read(preamble, sizeof preamble) != sizeof preamble)
            throw Error(source_.name(), source_.offset(), 0, "stream ends inside its 20-byte preamble");
        if (std::memcmp(preamble, kMagic, sizeof kMagic) != 0)
            throw Error(source_.name(), 0, 0, "not a meshstream triangle stream (bad magic bytes)");
        const uint32_t version = load_le<uint32_t>(preamble + 8);
        if (version != kVersion)
            throw Error(source_.name(), 8, 0,
                        "triangle stream version " + std::to_string(version) + " (this meshstream reads version 1)");
        const uint64_t body_bytes = load_le<uint64_t>(preamble + 12);
        // The header holds the material table, textures and all: within the memory budget.
        if (body_bytes > options.memory_budget_bytes)
            throw Error(source_.name(), 12, 0,
                        "header of " + std::to_string(body_bytes) +
                            " bytes (its material table) is over the memory "
                            "budget of " +
                            std::to_string(options.memory_budget_bytes) + " bytes; raise " + mention(Setting::kMemory));
        std::vector<std::byte> body(static_cast<size_t>(body_bytes));
        if (source_.read(body.data(), body.size()) != body.size())
            throw Error(source_.name(), source_.offset(), 0,
                        "stream ends inside its header (" + std::to_string(body_bytes) + " bytes announced)");
        parse_body(body);
        buffer_.resize(record_bytes_);
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        while (!chunk.full() && !ended_) {
            // A selection that ends before the stream does stops there (the end marker, which
            // counts every triangle, is the last range's to check).
            if (end_ && read_ == *end_ && *end_ < *header_.triangle_count) {
                ended_ = true;
                break;
            }
            if (left_in_chunk_ == 0) {
                read_chunk_start();
                continue;
            }
            // Decode whole records from the window in place; one straddling its end is copied.
            std::span<const std::byte> w = source_.window();
            const uint64_t wanted = end_ && *end_ < *header_.triangle_count ? *end_ - read_ : left_in_chunk_;
            size_t n = std::min<uint64_t>(
                {left_in_chunk_, wanted, chunk.capacity() - chunk.size(), w.size() / record_bytes_});
            if (n == 0) {
                if (source_.read(buffer_.data(), record_bytes_) != record_bytes_) truncated("inside a triangle record");
                decode(buffer_.data(), chunk);
                --left_in_chunk_;
                continue;
            }
            for (size_t i = 0; i < n; ++i) decode(w.data() + i * record_bytes_, chunk);
            source_.consume(n * record_bytes_);
            left_in_chunk_ -= n;
        }
        return !chunk.empty();
    }

    // A stream in a file that can seek, whose header states its count: goes to triangle `first`
    // past whole chunks (each chunk's count read, its records sought past) and stops before
    // `end`. A stream with fewer chunks than its count says is left to next() to report.
    bool select_triangles(uint64_t first, uint64_t end) override {
        if (read_ > 0 || left_in_chunk_ > 0 || ended_ || end_ || !header_.triangle_count || first > end ||
            end > *header_.triangle_count || !source_.size())
            return false;
        const uint64_t start = source_.offset();  // the first chunk's
        if (!source_.seek(start)) return false;   // (a gzip stream cannot)
        auto give_up = [&] {
            source_.seek(start);
            return false;
        };
        for (uint64_t at = start, passed = 0;;) {
            std::byte n_bytes[4];
            if (source_.read(n_bytes, 4) != 4) return give_up();
            const uint32_t n = load_le<uint32_t>(n_bytes);
            if (n == 0 || n > kMaxChunkTriangles) return give_up();  // the end marker before `first`
            if (passed + n > first) {
                if (!source_.seek(at + 4 + (first - passed) * record_bytes_)) return give_up();
                left_in_chunk_ = n - (first - passed);
                break;
            }
            passed += n;
            at += 4 + uint64_t{n} * record_bytes_;
            if (!source_.seek(at)) return give_up();
        }
        read_ = first;
        end_ = end;
        return true;
    }

private:
    void parse_body(const std::vector<std::byte>& body) {
        BodyCursor in(source_, body, kPreambleBytes);
        const uint64_t count = in.get<uint64_t>("the triangle count");
        if (count != kUnknownCount) header_.triangle_count = count;
        const uint8_t axis = in.get<uint8_t>("the sorted axis");
        if (axis <= 2)
            header_.sorted_axis = axis;
        else if (axis != kNoAxis)
            in.fail("sorted axis " + std::to_string(axis) + " (0, 1, 2 or 255)");
        const uint8_t flags = in.get<uint8_t>("the channel flags");
        if (flags & ~(kNormalFlag | kColorFlag | kVertexIdFlag))
            in.fail("unknown channel flags " + std::to_string(flags));
        const uint8_t color_code = in.get<uint8_t>("the colour type");
        const uint8_t alpha = in.get<uint8_t>("the colour alpha flag");
        const uint8_t uv_sets = in.get<uint8_t>("the uv set count");
        const uint8_t material = in.get<uint8_t>("the material flag");
        in.get<uint16_t>("reserved bytes");
        Channels& c = header_.channels;
        c.normal = flags & kNormalFlag;
        c.vertex_id = flags & kVertexIdFlag;
        if (flags & kColorFlag) {
            const std::optional<ScalarType> type = type_from_code(color_code);
            if (!type || (*type != ScalarType::kUInt8 && *type != ScalarType::kUInt16 && *type != ScalarType::kFloat32))
                in.fail("colour type " + std::to_string(color_code) + " (uchar, ushort or float)");
            c.color = ColorFormat{*type, alpha != 0};
        }
        if (uv_sets > kMaxUvSets) in.fail(std::to_string(uv_sets) + " uv sets (at most 4)");
        c.uv_sets = uv_sets;
        c.material = material != 0;
        c.vertex_scalars = get_scalars(in, "vertex scalar");
        c.face_scalars = get_scalars(in, "face scalar");
        const uint32_t materials = in.get<uint32_t>("the material count");
        for (uint32_t i = 0; i < materials; ++i) {
            Material m;
            m.name = in.string("a material name");
            for (float& v : m.base_color) v = in.get<float>("a base colour");
            if (in.get<uint8_t>("a texture flag")) {
                Texture t;
                t.uri = in.string("a texture uri");
                t.mime_type = in.string("a texture media type");
                t.bytes = in.bytes(in.get<uint64_t>("a texture size"), "a texture");
                m.texture = std::move(t);
            }
            header_.materials.push_back(std::move(m));
        }
        // Later minor versions may append fields: a version-1 reader reads what it knows.
        record_bytes_ = record_bytes(c);
        header_.variant = "version 1";
    }

    void read_chunk_start() {
        std::byte n_bytes[4];
        const size_t got = source_.read(n_bytes, 4);
        if (got != 4) truncated(got == 0 ? "before its end marker" : "inside a chunk's triangle count");
        const uint32_t n = load_le<uint32_t>(n_bytes);
        if (n > kMaxChunkTriangles)
            throw Error(source_.name(), source_.offset() - 4, 0,
                        "chunk of " + std::to_string(n) + " triangles (at most 16777216: a corrupt stream?)");
        if (n > 0) {
            left_in_chunk_ = n;
            return;
        }
        std::byte end[12];
        if (source_.read(end, sizeof end) != sizeof end) truncated("inside its end marker");
        const uint64_t count = load_le<uint64_t>(end);
        if (std::memcmp(end + 8, kEndTag, sizeof kEndTag) != 0)
            throw Error(source_.name(), source_.offset() - 4, 0, "bad end marker (expected 'MSHE')");
        if (count != read_)
            throw Error(
                source_.name(), source_.offset() - 12, 0,
                "end marker counts " + std::to_string(count) + " triangles, the stream holds " + std::to_string(read_));
        if (header_.triangle_count && *header_.triangle_count != read_)
            throw Error(source_.name(), source_.offset() - 12, 0,
                        "header promises " + std::to_string(*header_.triangle_count) + " triangles, stream holds " +
                            std::to_string(read_));
        if (!source_.at_end()) throw Error(source_.name(), source_.offset(), 0, "data after the end marker");
        ended_ = true;
    }

    [[noreturn]] void truncated(const char* where) const {
        throw Error(source_.name(), source_.offset(), 0,
                    std::string("stream is cut short ") + where + " (" + std::to_string(read_) + " triangles read)");
    }

    // Appends the record at `p` to `chunk`: positions and the channels the chunk has.
    void decode(const std::byte* p, TriangleChunk& chunk) {
        const Channels& c = header_.channels;
        const Channels& want = chunk.channels();
        float* xyz = chunk.push_slot();
        const size_t i = chunk.size() - 1;
        p = load_le_array(p, xyz, 9);
        if (c.normal) {
            if (want.normal) load_le_array(p, chunk.normal_at(i), 9);
            p += 9 * sizeof(float);
        }
        if (c.color) {
            if (want.color) load_le_array(p, chunk.color_at(i), 12);
            p += 12 * sizeof(float);
        }
        for (int s = 0; s < c.uv_sets; ++s) {
            if (s < want.uv_sets) load_le_array(p, chunk.uv_at(i, s), 6);
            p += 6 * sizeof(float);
        }
        for (const ScalarChannel& sc : c.vertex_scalars) {
            const auto it = std::find(want.vertex_scalars.begin(), want.vertex_scalars.end(), sc);
            if (it != want.vertex_scalars.end())
                load_le_array(p, chunk.vertex_scalar_at(i, size_t(it - want.vertex_scalars.begin())), 3);
            p += 3 * sizeof(double);
        }
        if (c.vertex_id) {
            if (want.vertex_id) load_le_array(p, chunk.id_at(i), 3);
            p += 3 * sizeof(uint64_t);
        }
        if (c.material) {
            if (want.material) load_le_array(p, chunk.material_at(i), 1);
            p += sizeof(uint32_t);
        }
        for (const ScalarChannel& sc : c.face_scalars) {
            const auto it = std::find(want.face_scalars.begin(), want.face_scalars.end(), sc);
            if (it != want.face_scalars.end())
                load_le_array(p, chunk.face_scalar_at(i, size_t(it - want.face_scalars.begin())), 1);
            p += sizeof(double);
        }
        ++read_;
    }

    ByteSource& source_;
    size_t record_bytes_ = 0;
    std::vector<std::byte> buffer_;  // one record straddling the window's end
    uint64_t left_in_chunk_ = 0;
    uint64_t read_ = 0;
    std::optional<uint64_t> end_;  // select_triangles()'s end
    bool ended_ = false;
};

// ---- writer ----

class StreamWriter final : public Writer {
public:
    StreamWriter(ByteSink& sink, const WriteOptions& options)
        : sink_(sink),
          channels_(options.channels),
          expected_(options.triangle_count),
          record_bytes_(record_bytes(options.channels)) {
        std::vector<std::byte> out(kMagic, kMagic + sizeof kMagic);
        const std::vector<std::byte> body = header_body(options);
        append_le(out, kVersion);
        append_le(out, static_cast<uint64_t>(body.size()));
        sink_.write(out.data(), out.size());
        sink_.write(body.data(), body.size());
    }

private:
    void write_chunk(const TriangleChunk& chunk) override {
        if (chunk.empty()) return;
        // A chunk of the stream holds at most kMaxChunkTriangles (larger caller chunks split).
        for (size_t first = 0; first < chunk.size(); first += kMaxChunkTriangles) {
            const size_t n = std::min<size_t>(chunk.size() - first, kMaxChunkTriangles);
            buffer_.resize(4 + n * record_bytes_);
            std::byte* p = buffer_.data();
            const uint32_t n32 = static_cast<uint32_t>(n);
            p = store_le_array(p, &n32, 1);
            for (size_t i = first; i < first + n; ++i) p = encode(chunk, i, p);
            sink_.write(buffer_.data(), buffer_.size());
        }
        written_ += chunk.size();
    }

    void finish_output() override {
        if (expected_ && *expected_ != written_)
            throw Error(sink_.name(),
                        "promised " + std::to_string(*expected_) + " triangles, wrote " + std::to_string(written_));
        std::vector<std::byte> end;
        append_le(end, uint32_t{0});
        append_le(end, written_);
        end.insert(end.end(), kEndTag, kEndTag + sizeof kEndTag);
        sink_.write(end.data(), end.size());
    }

    // Writes triangle i's record: positions, then the stream's channels (zeros for one the
    // chunk lacks, which the WriteOptions contract rules out).
    std::byte* encode(const TriangleChunk& chunk, size_t i, std::byte* p) const {
        const Channels& c = channels_;
        const Channels& has = chunk.channels();
        auto floats = [&](const float* src, size_t n) {
            if (src) return store_le_array(p, src, n);
            std::memset(p, 0, n * sizeof(float));
            return p + n * sizeof(float);
        };
        p = store_le_array(p, &chunk.xyz()[9 * i], 9);
        if (c.normal) p = floats(has.normal ? chunk.normal_at(i) : nullptr, 9);
        if (c.color) p = floats(has.color ? chunk.color_at(i) : nullptr, 12);
        for (int s = 0; s < c.uv_sets; ++s) p = floats(s < has.uv_sets ? chunk.uv_at(i, s) : nullptr, 6);
        for (const ScalarChannel& sc : c.vertex_scalars) {
            const auto it = std::find(has.vertex_scalars.begin(), has.vertex_scalars.end(), sc);
            const double zeros[3] = {0, 0, 0};
            p = store_le_array(p,
                               it != has.vertex_scalars.end()
                                   ? chunk.vertex_scalar_at(i, size_t(it - has.vertex_scalars.begin()))
                                   : zeros,
                               3);
        }
        if (c.vertex_id) {
            const uint64_t zeros[3] = {0, 0, 0};
            p = store_le_array(p, has.vertex_id ? chunk.id_at(i) : zeros, 3);
        }
        if (c.material) {
            const uint32_t zero = 0;
            p = store_le_array(p, has.material ? chunk.material_at(i) : &zero, 1);
        }
        for (const ScalarChannel& sc : c.face_scalars) {
            const auto it = std::find(has.face_scalars.begin(), has.face_scalars.end(), sc);
            const double zero = 0;
            p = store_le_array(
                p,
                it != has.face_scalars.end() ? chunk.face_scalar_at(i, size_t(it - has.face_scalars.begin())) : &zero,
                1);
        }
        return p;
    }

    ByteSink& sink_;
    Channels channels_;
    std::optional<uint64_t> expected_;
    size_t record_bytes_;
    std::vector<std::byte> buffer_;
    uint64_t written_ = 0;
};

std::unique_ptr<Reader> open_stream_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<StreamReader>(source, options);
}

std::unique_ptr<Writer> open_stream_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<StreamWriter>(sink, options);
}

// Every channel goes through.
Channels stream_keep_channels(const Channels& in, const WriteOptions&) { return in; }

}  // namespace

bool probe_triangle_stream(std::span<const std::byte> head) {
    return head.size() >= sizeof kMagic && std::memcmp(head.data(), kMagic, sizeof kMagic) == 0;
}

const Format kTriangleStreamFormat = {
    "stream",
    "mstream",
    "meshstream triangle stream: binary, count-free, every channel (the default on a pipe)",
    [](std::span<const std::byte> head, std::optional<uint64_t>) { return probe_triangle_stream(head); },
    &open_stream_reader,
    &open_stream_writer,
    0,
    nullptr,
    &stream_keep_channels,
};

}  // namespace meshstream::io
