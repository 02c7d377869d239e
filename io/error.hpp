// The one error family of meshstream's libraries. Every library call throws a meshstream::Error
// for what it cannot do:
//   - io::Error: a file that cannot be read or written, or bad input in it, carrying the file, the
//     position (byte offset and/or line) and a message, so that a program can print a
//     compiler-style diagnostic ("scan.stl:1207: expected 'endloop', found ...");
//   - io::OptionError: a setting given to a call that cannot work (a Draco position bit count
//     of 31, a target above the input's triangles), naming the setting (setting());
//   - meshstream::Error itself for the rest (memory the system refused for a buffer);
//   - engine::Cancelled once the caller's ProgressSink asked for it.
// Misuse of an object (a writer written to after finish(), a decimator pushed after finish())
// throws std::logic_error, an argument that breaks a precondition its header documents (a chunk
// of capacity 0, a NaN corner pushed into a decimator) std::invalid_argument, and memory
// exhausted std::bad_alloc, as in the standard library.
//
// Messages name the settings that matter (the remedy: "raise the memory budget") through
// io::mention(setting): what() words them for a library user ("the memory budget"), and a
// program with its own names for them (the command: "--memory") renders the same message with
// those (render(), describe()).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace meshstream::io {

// The settings a message may name.
enum class Setting : uint8_t {
    kInput,     // the input file
    kOutput,    // the output file
    kFrom,      // the input's format
    kTo,        // the output's format
    kMemory,    // the memory budget
    kTmpdir,    // the temporary directory
    kStrict,    // strict reading and writing
    kDrop,      // channel kinds not read
    kClean,     // bad triangles dropped
    kCompress,  // glTF compression
    kDracoPositionBits,
    kDracoNormalBits,
    kDracoTexcoordBits,
    kDracoColorBits,
    kDracoLevel,
    kGzipLevel,
    kRatio,
    kTarget,
    kBuffer,  // the decimator's buffer
    kWeld,
    kWeights,     // attribute weights
    kSortedAxis,  // the axis the input is sorted along
    kSeed,
    kThreads,
    kSort,         // the sort policy
    kAxis,         // the sort's axis
    kPart,         // a part job's index
    kMerge,        // the part files a merge reads
    kAttributes,   // what compare measures besides geometry
    kOutputChunk,    // the decimator's output chunk size
    kTileTriangles,  // a tile's triangle budget (tiles)
    kOrigin,         // where a tileset's origin is put on the globe
    kOverwrite,      // replacing a non-empty output directory
};
inline constexpr int kSettingCount = int(Setting::kOverwrite) + 1;

// The setting in a library user's words: "the memory budget", "strict mode".
std::string_view setting_words(Setting setting);
// A mark standing for `setting` in a message (an io::Error's, an io::OptionError's, a warning's).
std::string mention(Setting setting);
// `text` with every mention in the words `name` gives (setting_words when null).
using SettingNames = std::string (*)(Setting);
std::string render(std::string_view text, SettingNames name = nullptr);

}  // namespace meshstream::io

namespace meshstream {

class Error : public std::runtime_error {
public:
    // `message` may hold mentions (io::mention); what() words them as setting_words says.
    explicit Error(std::string message);
    // The message with the mentions in the words of `name`, and, for an io::Error, its position.
    virtual std::string describe(io::SettingNames name) const { return io::render(raw_, name); }
    // The same with the mentions kept, for a message that quotes this one.
    virtual std::string raw_what() const { return raw_; }

protected:
    Error(std::string what, std::string raw) : std::runtime_error(std::move(what)), raw_(std::move(raw)) {}

private:
    std::string raw_;
};

}  // namespace meshstream

namespace meshstream::io {

class Error : public meshstream::Error {
public:
    static constexpr uint64_t kNoOffset = ~uint64_t{0};

    // `line` is 1-based (0 = not known); `byte_offset` is kNoOffset when not known. `message`
    // may hold mentions.
    Error(std::string file, uint64_t byte_offset, uint64_t line, std::string message);
    // An error about a file as a whole (no position).
    Error(std::string file, std::string message);

    const std::string& file() const { return file_; }
    uint64_t byte_offset() const { return byte_offset_; }
    uint64_t line() const { return line_; }
    // The message without the position, in setting_words.
    std::string message() const { return render(message_); }
    // The same with the mentions kept, for an error that quotes this one.
    const std::string& raw_message() const { return message_; }
    std::string describe(SettingNames name) const override;
    std::string raw_what() const override;

private:
    std::string file_;
    uint64_t byte_offset_;
    uint64_t line_;
    std::string message_;
};

// A setting given to a library call that cannot work, named by setting(); the message says
// why, and with which value.
class OptionError : public meshstream::Error {
public:
    OptionError(Setting setting, std::string message) : meshstream::Error(std::move(message)), setting_(setting) {}
    Setting setting() const { return setting_; }

private:
    Setting setting_;
};

// Text from a file (or a library quoting one) for an error message, on one line: printable
// ASCII as it is, anything else (newlines too) as \xNN, cut with "..." after `max_chars`.
std::string printable(std::string_view text, size_t max_chars);

// Formats a (possibly binary) token for an error message: printable(token, 32), quoted.
std::string quote_token(std::string_view token);

}  // namespace meshstream::io
