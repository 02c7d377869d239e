// Byte stream tests: gzip round trips and damage, multi-member gzip, atomic sinks (no file
// without commit), patching, the window/peek/consume contract across refills, seeking in plain
// files, temporary files, and 64-bit sizes and offsets through a RawInput that fakes a binary
// STL over 4 GiB.
#include "io/byte_stream.hpp"

#include "io/error.hpp"
#include "io/format.hpp"
#include "io/stl.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace io = meshstream::io;
namespace fs = std::filesystem;

using meshstream::test::slurp;

namespace {

// Deterministic test data: half xorshift noise (incompressible), half repeated text.
std::string test_bytes(size_t n, uint64_t seed) {
    std::string out;
    out.reserve(n);
    uint64_t x = seed | 1;
    while (out.size() < n) {
        if ((out.size() / 4096) % 2 == 0) {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            out += static_cast<char>(x);
        } else {
            out += "vertex 1.5 2.5 3.5\n"[out.size() % 19];
        }
    }
    return out;
}

class MemoryInput : public io::RawInput {
public:
    MemoryInput(std::string bytes, bool sized, size_t piece) : bytes_(std::move(bytes)), sized_(sized), piece_(piece) {}
    size_t read(void* dst, size_t n) override {
        size_t take = std::min({n, piece_, bytes_.size() - pos_});
        std::memcpy(dst, bytes_.data() + pos_, take);
        pos_ += take;
        return take;
    }
    std::optional<uint64_t> size() const override {
        return sized_ ? std::optional<uint64_t>(bytes_.size()) : std::nullopt;
    }

private:
    std::string bytes_;
    bool sized_;
    size_t piece_;
    size_t pos_ = 0;
};

io::ByteSource memory_source(std::string bytes, bool sized = true, size_t piece = std::numeric_limits<size_t>::max()) {
    return io::ByteSource(std::make_unique<MemoryInput>(std::move(bytes), sized, piece), "mem");
}

// Reads a source to its end through window()/consume() in steps of at most `step` bytes.
std::string drain(io::ByteSource& source, size_t step = std::numeric_limits<size_t>::max()) {
    std::string out;
    for (auto w = source.window(); !w.empty(); w = source.window()) {
        size_t take = std::min(step, w.size());
        out.append(reinterpret_cast<const char*>(w.data()), take);
        source.consume(take);
    }
    return out;
}

class ByteStreamTest : public ::testing::Test {
protected:
    void SetUp() override {
        std::string pattern = (fs::temp_directory_path() / "byte_stream_test-XXXXXX").string();
        ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
        dir_ = pattern;
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // Writes `data` through a ByteSink (gzip when level >= 0) in uneven pieces and commits.
    std::string write_sink(const std::string& name, const std::string& data, int level) {
        auto sink = io::ByteSink::open(path(name), {level});
        size_t pos = 0;
        for (size_t piece : {size_t{1}, size_t{1000}, size_t{3} << 20, size_t{77}}) {
            size_t take = std::min(piece, data.size() - pos);
            sink->write(data.data() + pos, take);
            pos += take;
        }
        sink->write(data.data() + pos, data.size() - pos);
        EXPECT_EQ(sink->offset(), data.size());
        sink->commit();
        return slurp(path(name));
    }

    fs::path dir_;
};

TEST_F(ByteStreamTest, GzipRoundTripThroughSinkAndSource) {
    const std::string data = test_bytes(5 << 20, 42);
    const std::string gz = write_sink("a.bin.gz", data, 6);
    ASSERT_GE(gz.size(), 2u);
    EXPECT_EQ(gz.substr(0, 2), "\x1f\x8b");
    EXPECT_LT(gz.size(), data.size());

    auto source = io::ByteSource::open(path("a.bin.gz"));
    EXPECT_TRUE(source->gzip());
    EXPECT_FALSE(source->size().has_value());
    EXPECT_TRUE(source->regular_file_path().empty());
    // Mix the access paths: a peek, a small read, a large read that bypasses the buffer, windows.
    auto head = source->peek(100);
    ASSERT_EQ(head.size(), 100u);
    EXPECT_EQ(std::memcmp(head.data(), data.data(), 100), 0);
    std::string got(10, '\0');
    ASSERT_EQ(source->read(got.data(), 10), 10u);
    std::string big(3 << 20, '\0');
    ASSERT_EQ(source->read(big.data(), big.size()), big.size());
    got += big;
    got += drain(*source, 12345);
    EXPECT_TRUE(got == data);
    EXPECT_EQ(source->offset(), data.size());
    EXPECT_TRUE(source->at_end());

    // The plain twin: size known, path reported, same bytes.
    EXPECT_TRUE(write_sink("a.bin", data, -1) == data);
    auto plain = io::ByteSource::open(path("a.bin"));
    EXPECT_FALSE(plain->gzip());
    EXPECT_EQ(plain->size(), data.size());
    EXPECT_EQ(plain->regular_file_path(), path("a.bin"));
    EXPECT_TRUE(drain(*plain) == data);
}

TEST_F(ByteStreamTest, GzipCutAnywhereOrCorruptThrows) {
    const std::string data = test_bytes(2000, 7);  // ~1 KB of gzip: every cut is tried
    const std::string gz = write_sink("small.gz", data, 9);
    // Every cut from the 2-byte magic on ends inside a member: header, block or trailer.
    for (size_t length = 2; length < gz.size(); ++length) {
        SCOPED_TRACE(length);
        auto source = memory_source(gz.substr(0, length), false);
        EXPECT_TRUE(source.gzip());
        EXPECT_THROW(drain(source), io::Error);
    }
    // A cut mid-way through a large stream names the file and the compressed offset.
    const std::string big = write_sink("big.gz", test_bytes(4 << 20, 9), 1);
    std::string cut_path = path("cut.gz");
    {
        std::ofstream out(cut_path, std::ios::binary);
        out.write(big.data(), static_cast<std::streamsize>(big.size() / 2));
    }
    auto cut = io::ByteSource::open(cut_path);
    try {
        drain(*cut);
        ADD_FAILURE() << "no error for a cut gzip stream";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), cut_path);
        EXPECT_EQ(e.byte_offset(), big.size() / 2);
        EXPECT_NE(e.message().find("truncated"), std::string::npos) << e.what();
    }
    // A flipped byte in the middle is corrupt data (bad block or CRC), never silent.
    std::string flipped = gz;
    flipped[gz.size() / 2] = static_cast<char>(flipped[gz.size() / 2] ^ 0x55);
    auto bad = memory_source(flipped);
    EXPECT_THROW(drain(bad), io::Error);
}

TEST_F(ByteStreamTest, MultiMemberGzipIsConcatenated) {
    const std::string a = test_bytes(300000, 1), b = test_bytes(5000, 2);
    std::string joined = write_sink("a.gz", a, 6) + write_sink("empty.gz", "", 6) + write_sink("b.gz", b, 6);
    for (size_t piece : {size_t{3}, std::numeric_limits<size_t>::max()}) {
        auto source = memory_source(joined, false, piece);
        EXPECT_TRUE(drain(source, 999) == a + b) << piece;
    }
}

TEST_F(ByteStreamTest, SinkWithoutCommitLeavesNoFile) {
    for (int level : {-1, 6}) {
        {
            auto sink = io::ByteSink::open(path("out.bin"), {level});
            std::string data = test_bytes(3 << 20, 3);
            sink->write(data);
            EXPECT_FALSE(fs::is_empty(dir_));  // the temporary file exists meanwhile
        }
        EXPECT_TRUE(fs::is_empty(dir_)) << level;
    }
    // An existing file is not touched by an abandoned sink.
    std::ofstream(path("keep.bin")) << "old";
    { io::ByteSink::open(path("keep.bin"))->write("new contents"); }
    EXPECT_EQ(slurp(path("keep.bin")), "old");
    // After commit exactly the target exists.
    write_sink("keep.bin", "new", -1);
    EXPECT_EQ(slurp(path("keep.bin")), "new");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// A sink is finished once: more writes or a second commit are errors, not a hang (a finished
// gzip stream consumes no input, and the compression loop used to wait for it forever).
TEST_F(ByteStreamTest, SinkUsedAfterCommitThrows) {
    for (int level : {-1, 6}) {
        auto sink = io::ByteSink::open(path("done.bin"), {level});
        sink->write("abc");
        sink->commit();
        EXPECT_THROW(sink->write("def"), io::Error) << level;
        EXPECT_THROW(sink->commit(), io::Error) << level;
        auto source = io::ByteSource::open(path("done.bin"));
        EXPECT_EQ(source->gzip(), level >= 0);
        std::string got(8, '\0');
        got.resize(source->read(got.data(), got.size()));
        EXPECT_EQ(got, "abc") << level;
    }
}

TEST_F(ByteStreamTest, SinkErrorsNameTheTarget) {
    try {
        io::ByteSink::open(path("no/such/dir/x.stl"));
        ADD_FAILURE() << "no error";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), path("no/such/dir/x.stl"));
    }
    EXPECT_THROW(io::ByteSink::open(dir_.string()), io::Error);
    EXPECT_THROW(io::ByteSource::open(path("missing.stl")), io::Error);
    EXPECT_THROW(io::ByteSource::open(dir_.string()), io::Error);
}

TEST_F(ByteStreamTest, SinkWritesThroughSymlinksAndKeepsPermissions) {
    // A link is followed: the file it names is replaced and the link stays a link.
    std::ofstream(path("real.stl")) << "old";
    fs::create_symlink("real.stl", path("link.stl"));
    write_sink("link.stl", "new", -1);
    EXPECT_TRUE(fs::is_symlink(path("link.stl")));
    EXPECT_EQ(slurp(path("real.stl")), "new");
    // A dangling link names the file to create.
    fs::create_symlink("sub/made.stl", path("dangling.stl"));
    fs::create_directory(path("sub"));
    write_sink("dangling.stl", "made", -1);
    EXPECT_TRUE(fs::is_symlink(path("dangling.stl")));
    EXPECT_EQ(slurp(path("sub/made.stl")), "made");
    // A replaced file keeps its mode.
    fs::permissions(path("real.stl"), fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
    write_sink("real.stl", "again", -1);
    EXPECT_EQ(fs::status(path("real.stl")).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST_F(ByteStreamTest, SinkWritesIntoAFifoInPlace) {
    // Renaming a file over a FIFO (or /dev/null) would replace it; it is written in place.
    ASSERT_EQ(::mkfifo(path("pipe").c_str(), 0600), 0);
    const int reader = ::open(path("pipe").c_str(), O_RDONLY | O_NONBLOCK);  // opens without a writer
    ASSERT_GE(reader, 0);
    std::string data = test_bytes(40000, 9);  // under a pipe's 64 KiB: no reader thread needed
    {
        auto sink = io::ByteSink::open(path("pipe"));
        EXPECT_FALSE(sink->patchable());
        sink->write(data);
        sink->commit();
    }
    EXPECT_TRUE(fs::is_fifo(path("pipe")));
    std::string got(data.size() + 1, '\0');
    const ssize_t n = ::read(reader, got.data(), got.size());
    ::close(reader);
    ASSERT_EQ(n, static_cast<ssize_t>(data.size()));
    got.resize(static_cast<size_t>(n));
    EXPECT_TRUE(got == data);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);  // no temp left
}

TEST_F(ByteStreamTest, PatchOverwritesEarlierBytesOfPlainFilesOnly) {
    auto sink = io::ByteSink::open(path("p.bin"));
    EXPECT_TRUE(sink->patchable());
    std::string data = test_bytes(2 << 20, 5);
    sink->write(data);
    sink->patch(10, "ABCD", 4);
    sink->write("tail");
    sink->patch(data.size() + 1, "X", 1);  // inside bytes still buffered
    sink->commit();
    std::string expected = data + "tail";
    expected.replace(10, 4, "ABCD");
    expected[data.size() + 1] = 'X';
    EXPECT_TRUE(slurp(path("p.bin")) == expected);
    EXPECT_FALSE(io::ByteSink::open(path("p.bin.gz"), {6})->patchable());
}

TEST(ByteSource, WindowPeekConsumeAcrossRefills) {
    const std::string data = test_bytes(3 << 20, 11);
    // A producer handing out 7 bytes per read: peek must still gather what it is asked for.
    auto source = memory_source(data, true, 7);
    EXPECT_FALSE(source.gzip());
    EXPECT_EQ(source.size(), data.size());
    auto p = source.peek(1000);
    ASSERT_EQ(p.size(), 1000u);
    EXPECT_EQ(std::memcmp(p.data(), data.data(), 1000), 0);
    EXPECT_EQ(source.offset(), 0u);  // peek consumes nothing
    auto w = source.window();
    ASSERT_GE(w.size(), 1000u);
    source.consume(999);
    EXPECT_EQ(source.offset(), 999u);
    p = source.peek(5);
    EXPECT_EQ(std::memcmp(p.data(), data.data() + 999, 5), 0);
    // peek is capped at the buffer size.
    p = source.peek(io::ByteSource::kBufferBytes + 10);
    EXPECT_EQ(p.size(), io::ByteSource::kBufferBytes);
    EXPECT_EQ(std::memcmp(p.data(), data.data() + 999, p.size()), 0);
    EXPECT_EQ(source.skip(1), 1u);
    EXPECT_EQ(source.skip(uint64_t{1} << 40), data.size() - 1000);  // skip stops at the end
    EXPECT_TRUE(source.at_end());
    EXPECT_TRUE(source.window().empty());
    EXPECT_TRUE(source.peek(10).empty());
    char c;
    EXPECT_EQ(source.read(&c, 1), 0u);
    EXPECT_EQ(source.offset(), data.size());

    // fail() reports the current offset.
    auto other = memory_source("abcdef");
    other.consume(0);
    other.skip(4);
    try {
        other.fail("bad thing");
        ADD_FAILURE();
    } catch (const io::Error& e) {
        EXPECT_STREQ(e.what(), "mem: byte 4: bad thing");
    }
}

TEST_F(ByteStreamTest, SeekMovesInAPlainFileOnly) {
    const std::string data = test_bytes(3 << 20, 7);
    write_sink("plain.bin", data, -1);
    write_sink("packed.bin.gz", data, 6);
    auto plain = io::ByteSource::open(path("plain.bin"));
    std::string got(100, '\0');
    ASSERT_EQ(plain->read(got.data(), 10), 10u);
    // Forward past the buffer, then back into bytes already read.
    for (const uint64_t at : {uint64_t{2} << 20, uint64_t{5}, uint64_t{0}}) {
        ASSERT_TRUE(plain->seek(at));
        EXPECT_EQ(plain->offset(), at);
        ASSERT_EQ(plain->read(got.data(), got.size()), got.size());
        EXPECT_EQ(got, data.substr(at, got.size())) << at;
    }
    ASSERT_TRUE(plain->seek(data.size()));
    EXPECT_TRUE(plain->at_end());
    auto packed = io::ByteSource::open(path("packed.bin.gz"));
    EXPECT_FALSE(packed->seek(5));
    ASSERT_EQ(packed->read(got.data(), got.size()), got.size());
    EXPECT_EQ(got, data.substr(0, got.size()));
}

TEST(ByteSource, TinyAndEmptyInputs) {
    for (std::string bytes : {std::string(), std::string("\x1f"), std::string("ab")}) {
        auto source = memory_source(bytes, false, 1);
        EXPECT_FALSE(source.gzip());
        EXPECT_EQ(drain(source), bytes);
    }
}

TEST_F(ByteStreamTest, TempFileWritesReadsAndRemovesItself) {
    std::string file_path;
    {
        io::TempFile temp(dir_.string(), "spill");
        file_path = temp.path();
        EXPECT_TRUE(fs::exists(file_path));
        std::string data = test_bytes(3 << 20, 13);
        temp.write(data.data(), 100);
        temp.write(data.data() + 100, data.size() - 100);  // larger than its buffer
        temp.write("xyz", 3);
        EXPECT_EQ(temp.size(), data.size() + 3);
        std::string back(50, '\0');
        temp.read_at(data.size() - 47, back.data(), 50);  // spans flushed and buffered bytes
        EXPECT_EQ(back, data.substr(data.size() - 47) + "xyz");
        EXPECT_THROW(temp.read_at(data.size(), back.data(), 50), io::Error);
    }
    EXPECT_FALSE(fs::exists(file_path));
}

// Temporary files created from several threads at once are all registered under their own
// path: an interrupt removes every one of them (the signal handler unlinks the registered
// paths, then dies of the signal).
TEST_F(ByteStreamTest, InterruptRemovesTempFilesCreatedConcurrently) {
    constexpr int kThreads = 4, kFilesPerThread = 24;
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        io::install_cleanup_handlers();
        std::vector<std::unique_ptr<io::TempFile>> files[kThreads];
        std::vector<std::thread> threads;
        for (int t = 0; t < kThreads; ++t)
            threads.emplace_back([&, t] {
                for (int i = 0; i < kFilesPerThread; ++i)
                    files[t].push_back(std::make_unique<io::TempFile>(dir_.string(), "spill"));
            });
        for (std::thread& t : threads) t.join();
        std::raise(SIGTERM);
        std::_Exit(3);  // not reached: SIGTERM's default action ends the process
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "child exited with status " << WEXITSTATUS(status);
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    int left = 0;
    for (const auto& entry : fs::directory_iterator(dir_)) {
        ADD_FAILURE() << "left behind: " << entry.path();
        ++left;
    }
    EXPECT_EQ(left, 0);
}

// A binary STL of `count` synthetic facets that is never stored: bytes are computed from their
// position. Facet j has vertices (j,0,0), (j,1,0), (j,0,1). With fill off, read() only advances
// (to skip gigabytes quickly); `extra` trailing bytes make the size disagree with the count.
class SyntheticStl : public io::RawInput {
public:
    SyntheticStl(uint32_t count, uint64_t extra) : count_(count), size_(84 + uint64_t{50} * count + extra) {}
    size_t read(void* dst, size_t n) override {
        size_t take = static_cast<size_t>(std::min<uint64_t>(n, size_ - pos_));
        if (fill) {
            auto* out = static_cast<unsigned char*>(dst);
            for (size_t i = 0; i < take; ++i) out[i] = byte_at(pos_ + i);
        }
        pos_ += take;
        return take;
    }
    std::optional<uint64_t> size() const override { return size_; }
    uint64_t position() const { return pos_; }
    static void facet_xyz(uint64_t j, float* xyz) {
        const float f = static_cast<float>(j);
        const float v[9] = {f, 0, 0, f, 1, 0, f, 0, 1};
        std::memcpy(xyz, v, sizeof v);
    }
    unsigned char byte_at(uint64_t p) const {
        if (p < 80) return static_cast<unsigned char>("synthetic"[std::min<uint64_t>(p, 9)]);
        if (p < 84) return static_cast<unsigned char>(count_ >> (8 * (p - 80)));
        uint64_t j = (p - 84) / 50, k = (p - 84) % 50;
        if (k < 12 || k >= 48) return 0;
        float xyz[9];
        facet_xyz(j, xyz);
        unsigned char bytes[36];
        std::memcpy(bytes, xyz, sizeof bytes);  // little-endian host
        return bytes[k - 12];
    }

    bool fill = true;

private:
    uint32_t count_;
    uint64_t size_;
    uint64_t pos_ = 0;
};

TEST(ByteSource, SizesAndOffsetsPastFourGiB) {
    constexpr uint32_t kCount = 100'000'000;  // 84 + 50·n = 5,000,000,084 bytes > 4 GiB
    auto raw = std::make_unique<SyntheticStl>(kCount, 0);
    SyntheticStl* gen = raw.get();
    io::ByteSource source(std::move(raw), "huge.stl");
    ASSERT_EQ(source.size(), uint64_t{5'000'000'084});
    // Detected as binary STL by 84 + 50·n == size (needs 64-bit arithmetic) and streamed.
    const io::Format& format = io::detect_input_format(source);
    EXPECT_EQ(format.name, "stl");
    auto reader = format.open_reader(source, {});
    EXPECT_EQ(reader->triangle_count(), kCount);
    io::TriangleChunk chunk;
    uint64_t j = 0;
    for (int c = 0; c < 3; ++c) {
        ASSERT_TRUE(reader->next(chunk));
        ASSERT_TRUE(chunk.full());
        for (size_t t = 0; t < chunk.size(); ++t, ++j) {
            float want[9];
            SyntheticStl::facet_xyz(j, want);
            ASSERT_EQ(std::memcmp(&chunk.xyz()[9 * t], want, sizeof want), 0) << j;
        }
    }
    EXPECT_EQ(source.offset(), 84 + 50 * j);

    // Skip to beyond 4 GiB: offsets stay exact and the bytes there are the right ones.
    gen->fill = false;
    const uint64_t target_facet = 90'000'000;
    source.skip(84 + 50 * target_facet - source.offset());
    source.consume(source.window().size());  // drop unfilled buffered bytes
    EXPECT_EQ(source.offset(), gen->position());
    EXPECT_GT(source.offset(), uint64_t{1} << 32);
    gen->fill = true;
    const uint64_t facet = (source.offset() - 84 + 49) / 50;
    source.skip(84 + 50 * facet - source.offset());
    unsigned char bytes[50];
    ASSERT_EQ(source.read(bytes, 50), 50u);
    float want[9];
    SyntheticStl::facet_xyz(facet, want);
    EXPECT_EQ(std::memcmp(bytes + 12, want, sizeof want), 0);
    EXPECT_EQ(source.offset(), 84 + 50 * (facet + 1));

    // One stray byte past 5 GB: the size check reports it with 64-bit counts.
    io::ByteSource stray(std::make_unique<SyntheticStl>(kCount, 1), "stray.stl");
    try {
        io::kStlFormat.open_reader(stray, {});
        ADD_FAILURE() << "no error";
    } catch (const io::Error& e) {
        EXPECT_STREQ(e.what(),
                     "stray.stl: byte 84: header promises 100000000 triangles, file holds 100000000 "
                     "and 1 stray bytes");
    }
}

}  // namespace
