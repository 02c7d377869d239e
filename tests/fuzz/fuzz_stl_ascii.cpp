// libFuzzer target: the stl_ascii reader (kStlAsciiFormat) on arbitrary bytes, via fuzz_input.hpp.
#include "io/stl.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    meshstream::fuzz::read_all(meshstream::io::kStlAsciiFormat, data, size, "fuzz.stl");
    return 0;
}
