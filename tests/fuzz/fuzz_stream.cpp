// libFuzzer target: meshstream's triangle stream reader (kTriangleStreamFormat) on arbitrary
// bytes, via fuzz_input.hpp.
#include "io/triangle_stream.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    meshstream::fuzz::read_all(meshstream::io::kTriangleStreamFormat, data, size, "fuzz.mstream");
    return 0;
}
