// libFuzzer target: the gzip layer of ByteSource (GzipInput: zlib inflate, concatenated
// members, truncation). The input is prefixed with the gzip magic 1f 8b 08 unless it already
// starts with 1f 8b, so every run reaches the decoder; the decoded stream is then read to the
// end through window()/consume() and skip(), capped at 64 MiB (zip bombs are throughput, not
// bugs). Decoding through a format reader is covered by the reader targets on the seeds'
// decoded forms.
#include "tests/fuzz/fuzz_input.hpp"

#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace meshstream;
    std::vector<uint8_t> bytes;
    if (size < 2 || data[0] != 0x1f || data[1] != 0x8b) bytes = {0x1f, 0x8b, 0x08};
    bytes.insert(bytes.end(), data, data + size);
    try {
        io::ByteSource source(std::make_unique<fuzz::MemoryInput>(bytes.data(), bytes.size()), "fuzz.stl.gz");
        uint64_t total = 0;
        bool use_skip = size > 0 && (data[size - 1] & 1);
        while (total < (uint64_t{64} << 20)) {
            if (use_skip) {
                uint64_t n = source.skip(4097);
                if (n == 0) break;
                total += n;
            } else {
                std::span<const std::byte> w = source.window();
                if (w.empty()) break;
                source.consume(w.size());
                total += w.size();
            }
            if (source.offset() != total) __builtin_trap();  // offsets must count decoded bytes
        }
    } catch (const io::Error&) {}
    return 0;
}
