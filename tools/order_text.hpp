// The text `info --order` prints for a measured stream width (compare/order.hpp): the width,
// whether a decimation buffer suffices, and the sort keys' descents.
#pragma once

#include "compare/order.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace meshstream::tools {

// The text lines `info --order` prints ("width:", "buffer:", "key descents:"), judging
// `buffer_triangles` for decimation at `ratio`. `flagged_axis`: the axis the file says it is
// sorted along, if any (without one, a "suffices" warns that hole rims stay open to the end,
// which the width cannot tell; with one whose keys descend, the claim is called false).
std::string format_order_text(const compare::OrderReport& report, uint64_t buffer_triangles, double ratio,
                              std::optional<int> flagged_axis = std::nullopt);

}  // namespace meshstream::tools
