// TEMPORARY shim until the error family lands (replaced at merge).
#pragma once
#include <stdexcept>
#include <string>
namespace meshstream {
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};
}  // namespace meshstream
namespace meshstream::io {
enum class Setting : uint8_t { kMemory, kTmpdir, kStrict, kFrom, kTo, kDrop, kCompress, kBuffer, kWeld, kWeights, kTarget, kRatio, kSortedAxis, kSeed, kThreads, kPart, kMerge, kSort, kInput, kOutput, kAxis, kClean };
inline std::string mention(Setting s) {
    static const char* const names[] = {"--memory", "--tmpdir", "--strict", "--from", "--to", "--drop", "--compress", "--buffer", "--weld", "--weights", "--target", "--ratio", "--sorted-axis", "--seed", "--threads", "--part", "--merge", "--sort", "IN", "OUT", "--axis", "--clean"};
    return names[int(s)];
}
class OptionError : public meshstream::Error {
public:
    OptionError(Setting s, const std::string& m) : meshstream::Error(m), setting_(s) {}
    Setting setting() const { return setting_; }
private:
    Setting setting_;
};
}  // namespace meshstream::io
