// The text `info --order` prints for a measured width: the buffer verdict with the buffer it
// needs, exact and sampled.
#include "tools/order_text.hpp"

#include <gtest/gtest.h>

using namespace meshstream;

TEST(OrderText, SaysWhetherTheBufferSufficesAndWhatItNeeds) {
    compare::OrderReport r;
    r.triangles = 1000000;
    r.width = 500000;
    r.descents = {10, 20, 30000};
    const std::string exact = tools::format_order_text(r, 1200000, 0.1);
    EXPECT_NE(exact.find("width:       500000 triangles (exact), 50% of the file"), std::string::npos) << exact;
    EXPECT_NE(exact.find("--buffer 1200000 suffices at --ratio 0.1 (needs about 1200000)"), std::string::npos) << exact;
    EXPECT_NE(exact.find("key descents: x 10, y 20, z 30000"), std::string::npos) << exact;
    r.sample_rate = 1.0 / 16;
    r.width_error = 200000;
    const std::string sampled = tools::format_order_text(r, 400000, 0.1);
    EXPECT_NE(sampled.find("± 200000 (3σ; sampled 1/16"), std::string::npos) << sampled;
    EXPECT_NE(sampled.find("may be too small at --ratio 0.1 (needs about 1680000): the file is in no streaming order"),
              std::string::npos)
        << sampled;
}
