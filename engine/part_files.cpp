// Part files of `decimate --part k/K`: see part_files.hpp.
#include "engine/part_files.hpp"

#include "io/byte_stream.hpp"
#include "io/endian.hpp"
#include "io/error.hpp"
#include "io/hash.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <type_traits>

namespace meshstream::engine {
namespace {

static_assert(std::endian::native == std::endian::little, "part files are written in little-endian byte order");
static_assert(std::is_trivially_copyable_v<decimate::Stats>, "a range's stats are written as bytes");

constexpr char kMagic[8] = {'\x89', 'M', 'S', 'P', 'A', 'R', 'T', '\n'};
constexpr char kEndMagic[4] = {'M', 'S', 'P', 'E'};
constexpr uint32_t kVersion = 1;
constexpr uint8_t kPieceTag = 1, kEndTag = 2;
// A piece's header: tag, piece, weight, triangles.
constexpr size_t kPieceHeaderBytes = 1 + 1 + 8 + 8;
// The end: tag, stats, forced, forced_at, pieces, triangles, hash, magic.
constexpr size_t kEndBytes = 1 + sizeof(decimate::Stats) + 1 + 8 + 8 + 8 + 8 + 4;
// More triangles in one piece than any range writes at once: the file is not as written.
constexpr uint64_t kMaxPieceTriangles = uint64_t{1} << 24;
constexpr uint64_t kHashSeed = 0x9e3779b97f4a7c15ull;

using Put = io::ByteWriter;
using Get = io::ByteReader;

void put_scalars(Put& put, const std::vector<io::ScalarChannel>& scalars) {
    put.value(uint32_t(scalars.size()));
    for (const io::ScalarChannel& s : scalars) {
        put.text(s.name);
        put.value(uint8_t(s.type));
    }
}

std::vector<io::ScalarChannel> get_scalars(Get& get) {
    std::vector<io::ScalarChannel> scalars;
    const auto n = get.value<uint32_t>();
    for (uint32_t i = 0; i < n && get.ok() && i < 4096; ++i) {
        io::ScalarChannel s;
        s.name = get.text();
        s.type = io::ScalarType(get.value<uint8_t>());
        scalars.push_back(std::move(s));
    }
    if (n > 4096) get.fail();
    return scalars;
}

void put_plan(Put& put, const PartPlan& plan) {
    const decimate::Options& o = plan.options;
    put.value(o.ratio);
    put.value(uint8_t(plan.target.has_value()));
    put.value(plan.target.value_or(0));
    put.value(uint64_t(o.buffer_triangles));
    put.value(o.seed);
    put.value(o.weld_eps);
    put.value(int32_t(o.sorted_axis.value_or(-1)));
    put.value(uint8_t(o.sorted_by_minimum));
    put.value(uint64_t(o.output_chunk_triangles));
    put.value(plan.cut_triangles);
    put.value(uint32_t(plan.ranges));
    put.value(uint32_t(plan.omega.size()));
    for (const double w : plan.omega) put.value(w);
    const io::Channels& c = plan.channels;
    put.value(uint8_t(c.normal));
    put.value(uint8_t(c.color.has_value()));
    put.value(uint8_t(c.color ? c.color->type : io::ScalarType::kUInt8));
    put.value(uint8_t(c.color && c.color->alpha));
    put.value(int32_t(c.uv_sets));
    put_scalars(put, c.vertex_scalars);
    put.value(uint8_t(c.material));
    put_scalars(put, c.face_scalars);
}

PartPlan get_plan(Get& get) {
    PartPlan plan;
    decimate::Options& o = plan.options;
    o.ratio = get.value<double>();
    const bool has_target = get.value<uint8_t>() != 0;
    const auto target = get.value<uint64_t>();
    if (has_target) plan.target = target;
    o.buffer_triangles = size_t(get.value<uint64_t>());
    o.seed = get.value<uint64_t>();
    o.weld_eps = get.value<double>();
    if (const auto axis = get.value<int32_t>(); axis >= 0) o.sorted_axis = axis;
    o.sorted_by_minimum = get.value<uint8_t>() != 0;
    o.output_chunk_triangles = size_t(get.value<uint64_t>());
    plan.cut_triangles = get.value<uint64_t>();
    plan.ranges = get.value<uint32_t>();
    const auto weights = get.value<uint32_t>();
    for (uint32_t i = 0; i < weights && get.ok() && i < 4096; ++i) plan.omega.push_back(get.value<double>());
    if (weights > 4096) get.fail();
    io::Channels& c = plan.channels;
    c.normal = get.value<uint8_t>() != 0;
    const bool has_color = get.value<uint8_t>() != 0;
    const auto color_type = io::ScalarType(get.value<uint8_t>());
    const bool alpha = get.value<uint8_t>() != 0;
    if (has_color) c.color = io::ColorFormat{color_type, alpha};
    c.uv_sets = get.value<int32_t>();
    c.vertex_scalars = get_scalars(get);
    c.material = get.value<uint8_t>() != 0;
    c.face_scalars = get_scalars(get);
    return plan;
}

// The shortest text that reads back as `v`.
std::string number_text(double v) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
    return ec == std::errc() ? std::string(text, end) : std::string("?");
}

const char* axis_text(const std::optional<int>& axis) {
    static const char* const kNames[] = {"x", "y", "z"};
    return axis && *axis >= 0 && *axis < 3 ? kNames[*axis] : "none";
}

// How `part` (the file's plan) differs from `job` (this job's), as "was made with ..., this job
// has ..."; empty when they are the same. The settings are mentions (io::mention).
std::string plan_difference(const PartPlan& part, const PartPlan& job) {
    using io::mention;
    using io::Setting;
    const decimate::Options &a = part.options, &b = job.options;
    auto differs = [](const std::string& what, const std::string& x, const std::string& y) {
        return "was made with " + what + " " + x + ", this job has " + y;
    };
    using io::mention;
    using io::Setting;
    auto target_text = [](const std::optional<uint64_t>& t) { return t ? std::to_string(*t) : std::string("none"); };
    if (part.target != job.target)
        return differs(mention(Setting::kTarget), target_text(part.target), target_text(job.target));
    if (a.ratio != b.ratio)
        return "was made with the ranges decimating at ratio " + number_text(a.ratio) + ", this job's is " +
               number_text(b.ratio) + " (" + mention(Setting::kRatio) + " or " + mention(Setting::kTarget) + " differ)";
    if (a.buffer_triangles != b.buffer_triangles)
        return differs(mention(Setting::kBuffer), std::to_string(a.buffer_triangles),
                       std::to_string(b.buffer_triangles));
    if (a.seed != b.seed) return differs(mention(Setting::kSeed), std::to_string(a.seed), std::to_string(b.seed));
    if (a.weld_eps != b.weld_eps)
        return "was made welding on a grid of " + number_text(a.weld_eps) + ", this job's is " +
               number_text(b.weld_eps) + " (" + mention(Setting::kWeld) + " differs)";
    if (a.sorted_axis != b.sorted_axis)
        return differs("the input sorted along", axis_text(a.sorted_axis), axis_text(b.sorted_axis)) + " (" +
               mention(Setting::kSortedAxis) + " differs)";
    if (a.sorted_by_minimum != b.sorted_by_minimum)
        return std::string("was made with the input ") + (a.sorted_by_minimum ? "" : "not ") +
               "known to be sorted by triangle minimum, this job " + (b.sorted_by_minimum ? "" : "not ") + "(" +
               mention(Setting::kSortedAxis) + " differs)";
    if (a.output_chunk_triangles != b.output_chunk_triangles)
        return "was made by a build that writes chunks of " + std::to_string(a.output_chunk_triangles) +
               " triangles, this one " + std::to_string(b.output_chunk_triangles);
    if (part.ranges != job.ranges) return differs("ranges", std::to_string(part.ranges), std::to_string(job.ranges));
    if (part.cut_triangles != job.cut_triangles)
        return "was made cutting " + std::to_string(part.cut_triangles) + " triangles into ranges, this job cuts " +
               std::to_string(job.cut_triangles);
    if (part.channels != job.channels) {
        const std::string more = io::describe_missing(part.channels, job.channels);
        const std::string less = io::describe_missing(job.channels, part.channels);
        std::string text = "carries other channels than this job";
        if (!more.empty()) text += ": it carries " + more + ", which this job does not";
        if (!less.empty()) text += std::string(more.empty() ? ": " : "; ") + "this job carries " + less;
        return text + " (the channels carried depend on the merge's output format and " + mention(Setting::kDrop) +
               ": give every part the merge's " + mention(Setting::kDrop) + ", and " + mention(Setting::kTo) +
               " naming its output format)";
    }
    if (part.omega != job.omega) return "was made with other " + mention(Setting::kWeights);
    return {};
}

std::string build_text() { return std::string("meshstream ") + MESHSTREAM_VERSION; }

std::string part_text(unsigned k, unsigned parts) { return std::to_string(k) + "/" + std::to_string(parts); }

// Reads exactly n bytes at `offset` of `fd`; false when the file ends first.
bool read_at(int fd, uint64_t offset, void* dst, size_t n, const std::string& path) {
    auto* p = static_cast<char*>(dst);
    for (size_t got = 0; got < n;) {
        const ssize_t r = ::pread(fd, p + got, n - got, off_t(offset + got));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) throw io::Error(path, std::string("cannot read: ") + std::strerror(errno));
        if (r == 0) return false;
        got += size_t(r);
    }
    return true;
}

// An open file descriptor, closed at the end of its scope.
class Fd {
public:
    explicit Fd(const std::string& path) : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
        if (fd_ < 0) throw io::Error(path, std::string("cannot open: ") + std::strerror(errno));
    }
    ~Fd() { ::close(fd_); }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    int get() const { return fd_; }

private:
    int fd_;
};

uint64_t file_size(int fd, const std::string& path) {
    struct stat st {};
    if (::fstat(fd, &st) != 0) throw io::Error(path, std::string("cannot stat: ") + std::strerror(errno));
    return uint64_t(st.st_size);
}

}  // namespace

std::optional<PartIndex> parse_part(const std::string& text) {
    const size_t slash = text.find('/');
    if (slash == std::string::npos) return std::nullopt;
    unsigned k = 0, parts = 0;
    const char* begin = text.data();
    const char* end = begin + text.size();
    const auto a = std::from_chars(begin, begin + slash, k);
    const auto b = std::from_chars(begin + slash + 1, end, parts);
    if (slash == 0 || a.ec != std::errc() || a.ptr != begin + slash || b.ec != std::errc() || b.ptr != end ||
        !std::isdigit(static_cast<unsigned char>(text[slash + 1])))
        return std::nullopt;
    if (parts < 2 || parts > 1024 || k < 1 || k > parts) return std::nullopt;
    return PartIndex{k, parts};
}

InputFingerprint fingerprint_file(const std::string& path) {
    const Fd fd(path);
    InputFingerprint f;
    f.size = file_size(fd.get(), path);
    uint64_t h = io::mix64(f.size ^ kHashSeed);
    std::vector<char> block;
    auto take = [&](uint64_t offset, uint64_t bytes) {
        bytes = std::min(bytes, f.size - std::min(offset, f.size));
        block.resize(size_t(bytes));
        if (!read_at(fd.get(), offset, block.data(), block.size(), path))
            throw io::Error(path, "file shorter than its size while fingerprinting it");
        h = io::hash_bytes(reinterpret_cast<const std::byte*>(block.data()), block.size(), h);
    };
    constexpr uint64_t kEnds = 64 << 10, kBlock = 4 << 10;
    take(0, kEnds);
    for (uint64_t i = 1; i <= 14; ++i) take(f.size / 15 * i, kBlock);
    take(f.size > kEnds ? f.size - kEnds : 0, kEnds);
    f.hash = h;
    return f;
}

PartFileSink::PartFileSink(const std::string& path, PartIndex index, const InputFingerprint& input,
                           const PartPlan& plan)
    : sink_(io::ByteSink::open(path)), records_(plan.channels), hash_(kHashSeed) {
    Put body;
    body.text(build_text());
    body.value(uint32_t(index.k));
    body.value(uint32_t(index.parts));
    body.value(input.size);
    body.value(input.hash);
    put_plan(body, plan);
    body.value(uint32_t(records_.bytes()));
    body.value(uint32_t(sizeof(decimate::Stats)));
    Put head;
    head.raw_bytes(kMagic, sizeof kMagic);
    head.value(kVersion);
    head.value(uint32_t(body.size()));
    sink_->write(head.data(), head.size());
    sink_->write(body.data(), body.size());
}

PartFileSink::~PartFileSink() = default;

void PartFileSink::put(const void* data, size_t n) {
    sink_->write(data, n);
    hash_ = io::hash_bytes(static_cast<const std::byte*>(data), n, hash_);
}

void PartFileSink::append(const io::TriangleChunk& chunk, double weight, Piece piece) {
    Put head;
    head.value(kPieceTag);
    head.value(uint8_t(piece));
    head.value(weight);
    head.value(uint64_t(chunk.size()));
    put(head.data(), head.size());
    bytes_.clear();
    records_.encode(chunk, bytes_);
    put(bytes_.data(), bytes_.size());
    ++pieces_;
    triangles_ += chunk.size();
}

void PartFileSink::close(const RangeOutcome& outcome, std::exception_ptr error) {
    error_ = error;
    if (error_) return;  // the temporary file goes with the sink
    try {
        Put end;
        end.value(kEndTag);
        end.raw(outcome.stats);
        end.value(uint8_t(outcome.forced));
        end.value(outcome.forced_at);
        end.value(pieces_);
        end.value(triangles_);
        // The hash covers the end's figures too: a damaged one is refused, not summed.
        const uint64_t hash = io::hash_bytes(end.data(), end.size(), hash_);
        end.value(hash);
        end.raw_bytes(kEndMagic, sizeof kEndMagic);
        sink_->write(end.data(), end.size());
        sink_->commit();
    } catch (...) {
        error_ = std::current_exception();
    }
}

uint64_t PartFileSink::bytes() const { return sink_->offset(); }

PartFileReader::PartFileReader(const std::string& path, unsigned parts, const InputFingerprint& input,
                               const PartPlan& plan)
    : path_(path) {
    const Fd fd(path);
    file_bytes_ = file_size(fd.get(), path);
    auto bad = [&](const std::string& what) { return io::Error(path, "not a complete part file: " + what); };
    char head[16];
    if (!read_at(fd.get(), 0, head, sizeof head, path)) throw bad("shorter than a part file's header");
    if (std::memcmp(head, kMagic, sizeof kMagic) != 0)
        throw io::Error(path, "not a part file (meshstream decimate --part k/K writes them)");
    Get head_fields(head + sizeof kMagic, sizeof head - sizeof kMagic);
    const auto version = head_fields.value<uint32_t>();
    const auto body_bytes = head_fields.value<uint32_t>();
    if (version != kVersion)
        throw io::Error(path, "part file of version " + std::to_string(version) + ", this build reads version " +
                                  std::to_string(kVersion));
    if (body_bytes > (1u << 20) || sizeof head + body_bytes > file_bytes_)
        throw bad("its header says " + std::to_string(body_bytes) + " bytes, the file holds " +
                  std::to_string(file_bytes_));
    std::vector<char> body(body_bytes);
    if (!read_at(fd.get(), sizeof head, body.data(), body.size(), path)) throw bad("its header is cut short");
    header_bytes_ = sizeof head + body_bytes;
    Get get(body.data(), body.size());
    const std::string build = get.text();
    if (get.ok() && build != build_text())
        throw io::Error(path,
                        "was made by " + build + ", this is " + build_text() + ": make every part with one build");
    k_ = get.value<uint32_t>();
    const auto file_parts = get.value<uint32_t>();
    InputFingerprint made_from;
    made_from.size = get.value<uint64_t>();
    made_from.hash = get.value<uint64_t>();
    const PartPlan file_plan = get_plan(get);
    const auto record_bytes = get.value<uint32_t>();
    const auto stats_bytes = get.value<uint32_t>();
    if (!get.ok()) throw bad("its header is cut short");
    if (stats_bytes != sizeof(decimate::Stats))
        throw io::Error(path, "was made by another build of " + build_text() + " (its statistics take " +
                                  std::to_string(stats_bytes) + " bytes, this build's " +
                                  std::to_string(sizeof(decimate::Stats)) + "): make every part with one build");
    const std::string name = "part " + part_text(k_, file_parts);
    if (file_parts != parts || k_ < 1 || k_ >= parts)
        throw io::Error(path, name + " is not one of parts 1/" + std::to_string(parts) + " to " +
                                  part_text(parts - 1, parts) + " of this job (" + io::mention(io::Setting::kPart) +
                                  " " + part_text(parts, parts) + ")");
    if (made_from.size != input.size)
        throw io::Error(path, name + " was made from an input of " + std::to_string(made_from.size) +
                                  " bytes, this job's has " + std::to_string(input.size));
    if (made_from.hash != input.hash)
        throw io::Error(path, name + " was made from another input of the same size (or this one changed since)");
    if (const std::string difference = plan_difference(file_plan, plan); !difference.empty())
        throw io::Error(path, name + " " + difference);
    record_bytes_ = io::TriangleRecords(plan.channels).bytes();
    if (record_bytes != record_bytes_)
        throw io::Error(path, name + " has records of " + std::to_string(record_bytes) + " bytes, this build writes " +
                                  std::to_string(record_bytes_));

    // The end: present, so the file was written to its end (a part is renamed into place only
    // complete; this finds a copy cut short).
    if (file_bytes_ < header_bytes_ + kEndBytes) throw bad("cut short (it has no end)");
    std::vector<char> end(kEndBytes);
    if (!read_at(fd.get(), file_bytes_ - kEndBytes, end.data(), end.size(), path)) throw bad("cut short");
    if (end[0] != char(kEndTag) || std::memcmp(end.data() + kEndBytes - 4, kEndMagic, 4) != 0)
        throw bad("cut short or damaged (its last bytes are not a part file's end)");
    Get end_fields(end.data() + 1, end.size() - 1);
    outcome_.stats = end_fields.raw<decimate::Stats>();
    outcome_.forced = end_fields.value<uint8_t>() != 0;
    outcome_.forced_at = end_fields.value<uint64_t>();
    pieces_ = end_fields.value<uint64_t>();
    triangles_ = end_fields.value<uint64_t>();
    hash_ = end_fields.value<uint64_t>();
    const uint64_t expected = header_bytes_ + pieces_ * kPieceHeaderBytes + triangles_ * record_bytes_ + kEndBytes;
    if (pieces_ > file_bytes_ || triangles_ > file_bytes_ || expected != file_bytes_)
        throw bad("its end counts " + std::to_string(pieces_) + " pieces of " + std::to_string(triangles_) +
                  " triangles, which take " + std::to_string(expected) + " bytes; the file has " +
                  std::to_string(file_bytes_));
    // Every piece read once before the merge starts: a damaged one is refused before any work
    // (read again by feed(), from the page cache, and checked again there).
    read_pieces([](Piece, double, size_t, const char*) { return true; });
}

bool PartFileReader::read_pieces(
    const std::function<bool(Piece piece, double weight, size_t triangles, const char* records)>& each) const {
    const Fd fd(path_);
    uint64_t offset = header_bytes_, pieces = 0, triangles = 0, hash = kHashSeed;
    std::vector<char> bytes;
    while (pieces < pieces_) {
        char head[kPieceHeaderBytes];
        if (!read_at(fd.get(), offset, head, sizeof head, path_))
            throw io::Error(path_, offset, 0, "part file cut short while it was read");
        Get fields(head + 1, sizeof head - 1);
        const auto piece = fields.value<uint8_t>();
        const auto weight = fields.value<double>();
        const auto n = fields.value<uint64_t>();
        if (head[0] != char(kPieceTag) || piece > uint8_t(Piece::kLastSeam) || !(weight >= 1) ||
            !std::isfinite(weight) || n > kMaxPieceTriangles || n > triangles_ - triangles)
            throw io::Error(path_, offset, 0, "damaged part file: expected a piece's header, found other bytes");
        hash = io::hash_bytes(reinterpret_cast<const std::byte*>(head), sizeof head, hash);
        offset += sizeof head;
        bytes.resize(size_t(n) * record_bytes_);
        if (!read_at(fd.get(), offset, bytes.data(), bytes.size(), path_))
            throw io::Error(path_, offset, 0, "part file cut short while it was read");
        hash = io::hash_bytes(reinterpret_cast<const std::byte*>(bytes.data()), bytes.size(), hash);
        offset += bytes.size();
        if (!each(Piece(piece), weight, size_t(n), bytes.data())) return false;
        ++pieces;
        triangles += n;
    }
    // The end's figures, as the writer hashed them (all of the end but the hash and the magic).
    std::vector<char> end(kEndBytes - 12);
    if (!read_at(fd.get(), offset, end.data(), end.size(), path_))
        throw io::Error(path_, offset, 0, "part file cut short while it was read");
    hash = io::hash_bytes(reinterpret_cast<const std::byte*>(end.data()), end.size(), hash);
    if (hash != hash_)
        throw io::Error(path_, "damaged part file: its bytes are not the ones written (their hash differs)");
    return true;
}

void PartFileReader::feed(RangeSink& sink, const std::atomic<bool>& stop, const io::Channels& channels) const {
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    const io::TriangleRecords records(channels);
    const bool whole = read_pieces([&](Piece piece, double weight, size_t n, const char* bytes) {
        if (stop) return false;
        if (chunk.capacity() < n) chunk = io::TriangleChunk(n, channels);
        records.decode(bytes, n, chunk);
        sink.append(chunk, weight, piece);
        return true;
    });
    if (!whole) return sink.close({}, nullptr);
    sink.progress(outcome_.stats.triangles_in);
    sink.close(outcome_, nullptr);
}

}  // namespace meshstream::engine
