// libFuzzer target: the draco reader (kDracoFormat) on arbitrary bytes, via fuzz_input.hpp.
#include "io/draco.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    meshstream::fuzz::read_all(meshstream::io::kDracoFormat, data, size, "fuzz.drc");
    return 0;
}
