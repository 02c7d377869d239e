// Helpers for the indexed-format tests (PLY, OBJ, welding): a per-test temp directory,
// reading a whole file into flat arrays through the registry, writing triangles through a
// format, and a generated grid surface.
#pragma once

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/format.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace meshstream::test {

inline std::string fixture(const std::string& name) { return std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name; }

// A fresh directory under the system temp dir, removed with its contents at scope exit.
class TempDir {
public:
    TempDir() {
        std::string pattern = (std::filesystem::temp_directory_path() / "meshstream-test-XXXXXX").string();
        std::vector<char> buf(pattern.begin(), pattern.end());
        buf.push_back('\0');
        path_ = ::mkdtemp(buf.data());
    }
    ~TempDir() { std::filesystem::remove_all(path_); }
    std::string operator/(const std::string& name) const { return path_ + "/" + name; }
    const std::string& path() const { return path_; }
    // Names of the entries in the directory (to check that nothing was left behind).
    std::vector<std::string> entries() const {
        std::vector<std::string> out;
        for (const auto& e : std::filesystem::directory_iterator(path_)) out.push_back(e.path().filename().string());
        return out;
    }

private:
    std::string path_;
};

struct Soup {
    std::vector<float> xyz;       // 9 per triangle
    std::vector<uint8_t> rgb;     // 9 per triangle when the reader gives colour
    std::vector<uint64_t> ids;    // 3 per triangle when the reader gives vertex ids
    io::MeshHeader header;
    size_t triangles() const { return xyz.size() / 9; }
};

inline Soup read_soup(const std::string& path, size_t capacity = io::TriangleChunk::kDefaultCapacity,
                      io::ReadOptions options = {}, std::string_view from = {}) {
    io::Input in = io::open_input(path, from, options);
    Soup s;
    s.header = in.reader->header();
    io::TriangleChunk chunk(capacity, s.header.channels);
    while (in.reader->next(chunk)) {
        EXPECT_FALSE(chunk.empty());
        s.xyz.insert(s.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        s.rgb.insert(s.rgb.end(), chunk.rgb().begin(), chunk.rgb().end());
        s.ids.insert(s.ids.end(), chunk.vertex_ids().begin(), chunk.vertex_ids().end());
    }
    EXPECT_TRUE(chunk.empty());
    EXPECT_FALSE(in.reader->next(chunk));  // stays exhausted
    return s;
}

// The io::Error that reading `path` throws; a test failure (and a placeholder error) if none.
inline io::Error read_error(const std::string& path) {
    try {
        read_soup(path);
    } catch (const io::Error& e) {
        return e;
    }
    ADD_FAILURE() << path << ": no io::Error";
    return io::Error(path, "no error");
}

// Writes `xyz` (9 floats a triangle), in chunks of `capacity`, as format `to` (empty: by name).
inline void write_soup(const std::string& path, const std::vector<float>& xyz, std::string_view to = {},
                       io::WriteOptions options = {}, size_t capacity = 1000) {
    io::Output out = io::open_output(path, to, options);
    io::TriangleChunk chunk(capacity);
    for (size_t t = 0; t < xyz.size() / 9; ++t) {
        if (chunk.full()) {
            out.write(chunk);
            chunk.clear();
        }
        float tri[9];
        std::copy(xyz.begin() + 9 * t, xyz.begin() + 9 * t + 9, tri);
        chunk.push(tri);
    }
    if (!chunk.empty()) out.write(chunk);
    out.finish();
}

// Converts `from` to `to` through the registry (like `meshstream convert`).
inline void convert(const std::string& from, const std::string& to, std::string_view to_format = {},
                    uint64_t budget = uint64_t{256} << 20, size_t capacity = io::TriangleChunk::kDefaultCapacity) {
    io::ReadOptions ro;
    ro.memory_budget_bytes = budget;
    io::Input in = io::open_input(from, {}, ro);
    io::WriteOptions wo;
    wo.memory_budget_bytes = budget;
    wo.sorted_axis = in.reader->header().sorted_axis;
    io::Output out = io::open_output(to, to_format, wo);
    io::TriangleChunk chunk(capacity, in.reader->header().channels);
    while (in.reader->next(chunk)) out.write(chunk);
    out.finish();
}

inline std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

inline void spit(const std::string& path, std::string_view bytes) {
    // A new file, not a truncated one: ext4 flushes files truncated and rewritten
    // (auto_da_alloc), which made loops over many small files wait on the disk.
    std::filesystem::remove(path);
    std::ofstream f(path, std::ios::binary);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// A wavy n × n vertex grid: 2 (n-1)^2 triangles sharing vertices, with irregular floats.
inline std::vector<float> grid_soup(int n) {
    auto z = [](int i, int j) { return 0.001f * static_cast<float>((i * 7919 + j * 104729) % 1000) - 0.37f; };
    std::vector<float> out;
    out.reserve(size_t(2) * (n - 1) * (n - 1) * 9);
    auto put = [&](int i, int j) {
        out.push_back(static_cast<float>(i) * 0.1f + 1e-3f);
        out.push_back(static_cast<float>(j) * 0.3f - 7.0f);
        out.push_back(z(i, j));
    };
    for (int i = 0; i + 1 < n; ++i)
        for (int j = 0; j + 1 < n; ++j) {
            put(i, j), put(i + 1, j), put(i + 1, j + 1);
            put(i, j), put(i + 1, j + 1), put(i, j + 1);
        }
    return out;
}

}  // namespace meshstream::test
