// Byte sizes in messages about --memory (io/text_number.hpp).
#include "io/text_number.hpp"

#include <gtest/gtest.h>

namespace {

using meshstream::io::binary_size;

TEST(BinarySize, UsesTheUnitsMemoryIsGivenIn) {
    EXPECT_EQ(binary_size(0), "0 bytes");
    EXPECT_EQ(binary_size(1), "1 byte");  // not "1 MiB": a tiny budget is shown as it is
    EXPECT_EQ(binary_size(1023), "1023 bytes");
    EXPECT_EQ(binary_size(1024), "1 KiB");
    EXPECT_EQ(binary_size(1536), "1.5 KiB");
    EXPECT_EQ(binary_size(98 * 1024 + 100), "98 KiB");
    EXPECT_EQ(binary_size(uint64_t{1} << 20), "1 MiB");
    EXPECT_EQ(binary_size(1536 * 1024), "1.5 MiB");
    EXPECT_EQ(binary_size(uint64_t{256} << 20), "256 MiB");
    EXPECT_EQ(binary_size(uint64_t{3} << 30), "3 GiB");
    EXPECT_EQ(binary_size(uint64_t{5000} << 30), "4.9 TiB");
    EXPECT_EQ(binary_size(uint64_t{20000} << 30), "20 TiB");  // no unit past TiB
}

}  // namespace
