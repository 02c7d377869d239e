// libFuzzer target: the ply reader (kPlyFormat) on arbitrary bytes, via fuzz_input.hpp.
#include "io/ply.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    meshstream::fuzz::read_all(meshstream::io::kPlyFormat, data, size, "fuzz.ply");
    return 0;
}
