// How a long library call reports its progress and is cancelled. The caller passes a
// ProgressSink (the command's progress bar is one; a Python binding another); the engine calls
// phase() when a new step starts, update() after every chunk (cheap: a sink that draws decides
// itself how often), and looks at cancelled() between chunks: once it says true, the call stops
// there, removes what it was writing and throws engine::Cancelled.
#pragma once

#include "io/error.hpp"

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

namespace meshstream::engine {

class ProgressSink {
public:
    virtual ~ProgressSink() = default;
    // A new step: its label ("decimating", "sorting: reading") and the count it goes to, when
    // known.
    virtual void phase(std::string label, std::optional<uint64_t> total) = 0;
    // Triangles (or the step's own unit) done so far in this step.
    virtual void update(uint64_t done) = 0;
    // The same while reading a file of `file_bytes` bytes as stored (nullopt: not a regular
    // file), of which `bytes_read` are read: the share done is best told from the bytes.
    virtual void update(uint64_t done, uint64_t bytes_read, std::optional<uint64_t> file_bytes) = 0;
    // A last step that reports no counts (a writer assembling its file).
    virtual void status(const std::string& text) = 0;
    // True once the caller wants the call to stop.
    virtual bool cancelled() const { return false; }
};

// A sink that shows nothing, cancelled once `cancel` (when given) is set.
class QuietProgress final : public ProgressSink {
public:
    explicit QuietProgress(const std::atomic<bool>* cancel = nullptr) : cancel_(cancel) {}
    void phase(std::string, std::optional<uint64_t>) override {}
    void update(uint64_t) override {}
    void update(uint64_t, uint64_t, std::optional<uint64_t>) override {}
    void status(const std::string&) override {}
    bool cancelled() const override { return cancel_ != nullptr && cancel_->load(); }

private:
    const std::atomic<bool>* cancel_;
};

// Thrown by a call whose ProgressSink said cancelled(): nothing of its output is left behind.
class Cancelled : public meshstream::Error {
public:
    Cancelled() : meshstream::Error("cancelled") {}
};

// Throws Cancelled once `progress` says cancelled().
inline void throw_if_cancelled(const ProgressSink& progress) {
    if (progress.cancelled()) throw Cancelled();
}

}  // namespace meshstream::engine
