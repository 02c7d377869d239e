// format_order_text: see order_text.hpp.
#include "tools/order_text.hpp"

#include <cstdio>

namespace meshstream::tools {
namespace {

const char* const kAxisNames[] = {"x", "y", "z"};

}  // namespace

using compare::buffer_needed;
using compare::buffer_verdict;
using compare::BufferVerdict;
using compare::OrderReport;

std::string format_order_text(const OrderReport& r, uint64_t buffer_triangles, double ratio,
                              std::optional<int> flagged_axis) {
    const bool flagged_sorted = flagged_axis && r.descents[*flagged_axis] == 0;
    std::string out = "width:       " + std::to_string(r.width) + " triangles";
    char buf[160];
    if (r.exact()) {
        out += " (exact)";
    } else {
        std::snprintf(buf, sizeof buf, " ± %.0f (3σ; sampled 1/%.0f of the triangles to fit --memory)", r.width_error,
                      1 / r.sample_rate);
        out += buf;
    }
    if (r.triangles > 0) {
        std::snprintf(buf, sizeof buf, ", %.3g%% of the file, reached at triangle %llu\n",
                      100.0 * static_cast<double>(r.width) / static_cast<double>(r.triangles),
                      static_cast<unsigned long long>(r.width_at));
        out += buf;
    } else {
        out += "\n";
    }
    const BufferVerdict v = buffer_verdict(r, buffer_triangles, ratio);
    std::snprintf(buf, sizeof buf, " at --ratio %g (needs about %llu)", ratio,
                  static_cast<unsigned long long>(buffer_needed(r, ratio)));
    out += "buffer:      --buffer " + std::to_string(buffer_triangles) +
           (v == BufferVerdict::kSuffices   ? " suffices"
            : v == BufferVerdict::kTooSmall ? " is too small (decimate would force-write)"
                                            : " may be too small") +
           buf;
    // A surface in streaming order is a few percent wide at most (the bunny sorted: 1.1 %, a
    // 1 M mesh: 0.6 %); a shuffled one about three quarters: then sorting is the remedy.
    if (v != BufferVerdict::kSuffices && !flagged_sorted && r.width * 10 > r.triangles && r.triangles >= 10000)
        out +=
            ": the file is in no streaming order (its width is a tenth of it or more), so `meshstream sort` "
            "it first";
    if (v == BufferVerdict::kSuffices && !flagged_sorted)
        out += flagged_axis ? ", unless the surface has holes: the file is not sorted as it says, so their rims stay "
                              "open to the end"
                            : ", unless the surface has holes: the file is not flagged as sorted, so their rims stay "
                              "open to the end (`meshstream sort` flags it)";
    out += "\n";
    std::snprintf(buf, sizeof buf, "key descents: x %llu, y %llu, z %llu",
                  static_cast<unsigned long long>(r.descents[0]), static_cast<unsigned long long>(r.descents[1]),
                  static_cast<unsigned long long>(r.descents[2]));
    out += buf;
    const int axis = r.best_axis();
    if (r.triangles > 0 && r.descents[axis] == 0)
        out += std::string(" (sorted along ") + kAxisNames[axis] + " by minimum coordinate)";
    if (flagged_axis && r.descents[*flagged_axis] > 0)
        out += std::string(" (the file says it is sorted along ") + kAxisNames[*flagged_axis] +
               ", but it is not: `meshstream sort` it again)";
    out += "\n";
    return out;
}

}  // namespace meshstream::tools
