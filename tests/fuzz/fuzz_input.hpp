// Shared pieces of the libFuzzer targets: an in-memory RawInput over the fuzzer's bytes and a
// driver that opens one format's reader on it and pulls every chunk. io::Error is the only
// acceptable failure; any other exception escapes and libFuzzer reports it as a crash, as do
// sanitizer findings, hangs (-timeout) and allocations past -rss_limit_mb / -malloc_limit_mb.
#pragma once

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/format.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

namespace meshstream::fuzz {

// The fuzzer's bytes as a stream. Reports its size like a regular file, so readers take the
// same size-based paths (binary STL's 84 + 50·n check) as on disk.
class MemoryInput final : public io::RawInput {
public:
    MemoryInput(const uint8_t* data, size_t size) : data_(data), size_(size) {}
    size_t read(void* dst, size_t n) override {
        size_t k = std::min(n, size_ - pos_);
        if (k) std::memcpy(dst, data_ + pos_, k);
        pos_ += k;
        return k;
    }
    std::optional<uint64_t> size() const override { return size_; }

private:
    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
};

// Reads the whole input through `format`'s reader with small chunks (capacity 7, so chunk
// boundaries fall everywhere) and a 16 MiB memory budget (so spilling paths run too).
// Returns the triangle count read; io::Error is swallowed.
inline uint64_t read_all(const io::Format& format, const uint8_t* data, size_t size, const char* name) {
    uint64_t triangles = 0;
    try {
        io::ByteSource source(std::make_unique<MemoryInput>(data, size), name);
        io::ReadOptions options;
        options.memory_budget_bytes = uint64_t{16} << 20;
        std::unique_ptr<io::Reader> reader = format.open_reader(source, options);
        io::TriangleChunk chunk(7, reader->header().channels);
        while (reader->next(chunk)) {
            triangles += chunk.size();
            // Touch every coordinate so uninitialised values show up under MSan/valgrind.
            volatile float sink = 0;
            for (float v : chunk.xyz()) sink = sink + v;
        }
    } catch (const io::Error&) {}
    return triangles;
}

}  // namespace meshstream::fuzz
