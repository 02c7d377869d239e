// combine_ranges: the rules of for_each_stats_field applied, and the check that every field of
// Stats has one.
#include "decimate/stats.hpp"

#include "decimate/field_count.hpp"

#include <algorithm>
#include <stdexcept>
#include <type_traits>

namespace meshstream::decimate {

// Stats holds scalars only (no array or struct a brace could split), so field_count counts its
// fields; it stays trivially copyable (range files carry it as bytes).
static_assert(std::is_trivially_copyable_v<Stats>);
static_assert(field_count<Stats>() == stats_rule_count(),
              "every field of decimate::Stats needs its rule in for_each_stats_field (stats.hpp)");

Stats combine_ranges(const Stats& seams, std::span<const Stats> ranges, size_t buffer_capacity) {
    if (ranges.empty()) throw std::invalid_argument("decimate::combine_ranges needs at least one range");
    Stats whole;
    for_each_stats_field([&](auto field, auto rule) {
        auto& out = whole.*field;
        constexpr Combine how = decltype(rule)::value;
        if constexpr (how == Combine::kSeamPass) {
            out = seams.*field;
        } else if constexpr (how == Combine::kFirstRange) {
            out = ranges.front().*field;
        } else if constexpr (how == Combine::kBufferCapacity) {
            out = buffer_capacity;
        } else if constexpr (how == Combine::kRangesMax) {
            for (const Stats& r : ranges) out = std::max(out, r.*field);
        } else {
            static_assert(how == Combine::kRangesSum || how == Combine::kAllSum);
            out = how == Combine::kAllSum ? seams.*field : 0;
            for (const Stats& r : ranges) out += r.*field;
        }
    });
    return whole;
}

}  // namespace meshstream::decimate
