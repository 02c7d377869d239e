// Byte streams: POSIX file descriptors for files and stdio, zlib for gzip, mkstemp + rename
// for atomic output, and a signal-safe table of temporary paths to unlink on Ctrl-C.
#include "io/byte_stream.hpp"

#include "io/error.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string_view>

namespace meshstream::io {
namespace {

std::string errno_text() { return std::strerror(errno); }

class FdInput : public RawInput {
public:
    FdInput(int fd, bool owned, std::string name) : fd_(fd), owned_(owned), name_(std::move(name)) {
        struct stat st;
        if (fstat(fd_, &st) == 0 && S_ISREG(st.st_mode)) size_ = static_cast<uint64_t>(st.st_size);
    }
    ~FdInput() override {
        if (owned_) ::close(fd_);
    }
    size_t read(void* dst, size_t n) override {
        for (;;) {
            ssize_t got = ::read(fd_, dst, n);
            if (got >= 0) {
                pos_ += static_cast<uint64_t>(got);
                return static_cast<size_t>(got);
            }
            if (errno == EINTR) continue;
            throw Error(name_, pos_, 0, "read failed: " + errno_text());
        }
    }
    std::optional<uint64_t> size() const override { return size_; }
    uint64_t stored_offset() const override { return pos_; }
    bool seek(uint64_t offset) override {
        if (!size_ || ::lseek(fd_, off_t(offset), SEEK_SET) < 0) return false;
        pos_ = offset;
        return true;
    }

private:
    int fd_;
    bool owned_;
    std::string name_;
    uint64_t pos_ = 0;
    std::optional<uint64_t> size_;
};

// Inflates a gzip stream (several concatenated members allowed, as pigz and `cat a.gz b.gz`
// produce). The bytes already read while sniffing the magic are handed in as `prefix`.
class GzipInput : public RawInput {
public:
    GzipInput(std::unique_ptr<RawInput> raw, std::vector<std::byte> prefix, std::string name)
        : raw_(std::move(raw)), name_(std::move(name)), in_(std::make_unique_for_overwrite<std::byte[]>(kInBytes)) {
        std::memset(&zs_, 0, sizeof zs_);
        if (inflateInit2(&zs_, 16 + MAX_WBITS) != Z_OK) throw Error(name_, "zlib inflateInit failed");
        std::memcpy(in_.get(), prefix.data(), prefix.size());
        zs_.next_in = reinterpret_cast<Bytef*>(in_.get());
        zs_.avail_in = static_cast<uInt>(prefix.size());
        compressed_ = prefix.size();
    }
    ~GzipInput() override { inflateEnd(&zs_); }
    uint64_t stored_offset() const override { return compressed_ - zs_.avail_in; }
    std::optional<uint64_t> stored_size() const override { return raw_->stored_size(); }

    size_t read(void* dst, size_t n) override {
        if (done_) return 0;
        zs_.next_out = static_cast<Bytef*>(dst);
        zs_.avail_out = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
        const uInt want = zs_.avail_out;
        while (zs_.avail_out == want) {
            if (zs_.avail_in == 0) {
                size_t got = raw_->read(in_.get(), kInBytes);
                if (got == 0) {
                    if (member_started_)
                        throw Error(name_, compressed_, 0, "gzip stream is truncated (ends inside a compressed block)");
                    done_ = true;  // clean end after a complete member
                    break;
                }
                compressed_ += got;
                zs_.next_in = reinterpret_cast<Bytef*>(in_.get());
                zs_.avail_in = static_cast<uInt>(got);
            }
            member_started_ = true;
            int rc = inflate(&zs_, Z_NO_FLUSH);
            if (rc == Z_STREAM_END) {
                member_started_ = false;
                inflateReset(&zs_);
                continue;
            }
            if (rc != Z_OK && rc != Z_BUF_ERROR)
                throw Error(name_, compressed_ - zs_.avail_in, 0,
                            std::string("corrupt gzip data: ") + (zs_.msg ? zs_.msg : "inflate failed"));
        }
        return want - zs_.avail_out;
    }

private:
    static constexpr size_t kInBytes = size_t{1} << 18;
    std::unique_ptr<RawInput> raw_;
    std::string name_;
    std::unique_ptr<std::byte[]> in_;
    z_stream zs_;
    uint64_t compressed_ = 0;
    bool member_started_ = false;
    bool done_ = false;
};

// ---- temporary path table, unlinked by the signal handler ----
constexpr int kMaxTempPaths = 128;
constexpr size_t kMaxPathBytes = 1024;
char g_temp_paths[kMaxTempPaths][kMaxPathBytes];
// A slot is claimed (kTempClaimed) before its path is copied in and published (kTempReady)
// after, so neither a second thread nor the signal handler ever sees a half-written path.
enum : uint8_t { kTempFree, kTempClaimed, kTempReady };
std::atomic<uint8_t> g_temp_state[kMaxTempPaths];

extern "C" void cleanup_and_reraise(int sig) {
    for (int i = 0; i < kMaxTempPaths; ++i)
        if (g_temp_state[i].load() == kTempReady) ::unlink(g_temp_paths[i]);
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

mode_t default_file_mode() {
    static const mode_t mode = [] {
        mode_t mask = ::umask(0);
        ::umask(mask);
        return static_cast<mode_t>(0666 & ~mask);
    }();
    return mode;
}

void write_all(int fd, const void* data, size_t n, const std::string& name, uint64_t offset) {
    auto* p = static_cast<const char*>(data);
    while (n > 0) {
        ssize_t put = ::write(fd, p, n);
        if (put < 0) {
            if (errno == EINTR) continue;
            throw Error(name, offset, 0, "write failed: " + errno_text());
        }
        p += put;
        n -= static_cast<size_t>(put);
        offset += static_cast<uint64_t>(put);
    }
}

// The file a path names once symbolic links are followed (an output written through a link
// replaces the file it points to, not the link). A dangling link names its missing target.
std::string follow_symlinks(std::string path) {
    namespace fs = std::filesystem;
    for (int hops = 0; hops < 40; ++hops) {  // a loop of links: open() then reports ELOOP
        std::error_code ec;
        if (!fs::is_symlink(fs::symlink_status(path, ec))) return path;
        fs::path link = fs::read_symlink(path, ec);
        if (ec) return path;
        if (link.is_relative()) link = fs::path(path).parent_path() / link;
        path = link.string();
    }
    return path;
}

std::string make_temp(std::string pattern, int* fd, const std::string& what) {
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    *fd = ::mkstemp(buf.data());
    if (*fd < 0) throw Error(what, "cannot create temporary file " + pattern + ": " + errno_text());
    return std::string(buf.data());
}

}  // namespace

int register_temp_path(const std::string& path) {
    if (path.size() >= kMaxPathBytes) return -1;
    for (int i = 0; i < kMaxTempPaths; ++i) {
        uint8_t expected = kTempFree;
        if (g_temp_state[i].compare_exchange_strong(expected, kTempClaimed)) {
            std::memcpy(g_temp_paths[i], path.c_str(), path.size() + 1);
            g_temp_state[i].store(kTempReady);
            return i;
        }
    }
    return -1;  // table full: the file is still removed by its destructor
}

void unregister_temp_path(int slot) {
    if (slot >= 0) g_temp_state[slot].store(kTempFree);
}

void install_cleanup_handlers() {
    // SIGPIPE too: a reader that stops early (`| head`) ends the command mid-output, and it
    // should die quietly by that signal, as UNIX filters do, but without leaving its spools.
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) std::signal(sig, cleanup_and_reraise);
    // Past a file-size limit (ulimit -f) the kernel sends SIGXFSZ, whose default action kills
    // the process and leaves temporary files; ignored, write() fails with EFBIG instead and
    // the writer throws an io::Error like for a full disk.
    std::signal(SIGXFSZ, SIG_IGN);
}

std::string parent_dir(const std::string& path) {
    size_t slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    if (slash == 0) return "/";
    return path.substr(0, slash);
}

// ---------------- ByteSource ----------------

std::unique_ptr<ByteSource> ByteSource::open(const std::string& path) {
    std::unique_ptr<RawInput> raw;
    if (path == "-") {
        raw = std::make_unique<FdInput>(0, false, "<stdin>");
        return std::make_unique<ByteSource>(std::move(raw), "<stdin>");
    }
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(path, "cannot open: " + errno_text());
    struct stat st;
    if (fstat(fd, &st) == 0 && S_ISDIR(st.st_mode)) {
        ::close(fd);
        throw Error(path, "is a directory");
    }
    raw = std::make_unique<FdInput>(fd, true, path);
    bool regular = S_ISREG(st.st_mode);
    auto source = std::make_unique<ByteSource>(std::move(raw), path);
    if (regular && !source->gzip()) source->regular_path_ = path;
    return source;
}

ByteSource::ByteSource(std::unique_ptr<RawInput> raw, std::string name)
    : raw_(std::move(raw)), name_(std::move(name)), buf_(std::make_unique_for_overwrite<std::byte[]>(kBufferBytes)) {
    // Sniff the gzip magic (1f 8b) before anything else sees the bytes.
    size_t got = 0;
    while (got < 2) {
        size_t n = raw_->read(buf_.get() + got, 2 - got);
        if (n == 0) break;
        got += n;
    }
    if (got == 2 && buf_[0] == std::byte{0x1f} && buf_[1] == std::byte{0x8b}) {
        std::vector<std::byte> prefix(buf_.get(), buf_.get() + 2);
        raw_ = std::make_unique<GzipInput>(std::move(raw_), std::move(prefix), name_);
        gzip_ = true;
    } else {
        end_ = got;
        if (got < 2) eof_ = true;
    }
}

ByteSource::~ByteSource() = default;

std::optional<uint64_t> ByteSource::size() const {
    if (gzip_) return std::nullopt;
    return raw_->size();
}

bool ByteSource::fill(size_t want) {
    if (end_ - begin_ >= want) return true;
    if (begin_ > 0) {  // carry the unconsumed tail to the front
        std::memmove(buf_.get(), buf_.get() + begin_, end_ - begin_);
        end_ -= begin_;
        begin_ = 0;
    }
    while (end_ < want && !eof_) {
        size_t n = raw_->read(buf_.get() + end_, kBufferBytes - end_);
        if (n == 0) eof_ = true;
        end_ += n;
    }
    return end_ - begin_ >= want;
}

size_t ByteSource::read(void* dst, size_t n) {
    auto* out = static_cast<std::byte*>(dst);
    size_t done = 0;
    while (done < n) {
        if (begin_ == end_) {
            // Large reads bypass the buffer.
            if (n - done >= kBufferBytes && !eof_) {
                size_t got = raw_->read(out + done, n - done);
                if (got == 0) {
                    eof_ = true;
                    break;
                }
                done += got;
                offset_ += got;
                continue;
            }
            if (!fill(1)) break;
        }
        size_t take = std::min(n - done, end_ - begin_);
        std::memcpy(out + done, buf_.get() + begin_, take);
        begin_ += take;
        done += take;
        offset_ += take;
    }
    return done;
}

std::span<const std::byte> ByteSource::peek(size_t n) {
    if (n > kBufferBytes) n = kBufferBytes;
    fill(n);
    return {buf_.get() + begin_, std::min(n, end_ - begin_)};
}

std::span<const std::byte> ByteSource::window() {
    if (begin_ == end_) fill(1);
    return {buf_.get() + begin_, end_ - begin_};
}

void ByteSource::consume(size_t n) {
    assert(n <= end_ - begin_);
    begin_ += n;
    offset_ += n;
}

uint64_t ByteSource::skip(uint64_t n) {
    uint64_t done = 0;
    while (done < n) {
        auto w = window();
        if (w.empty()) break;
        size_t take = static_cast<size_t>(std::min<uint64_t>(n - done, w.size()));
        consume(take);
        done += take;
    }
    return done;
}

bool ByteSource::seek(uint64_t offset) {
    if (gzip_ || !raw_->seek(offset)) return false;
    begin_ = end_ = 0;
    offset_ = offset;
    eof_ = false;
    return true;
}

bool ByteSource::at_end() { return window().empty(); }

void ByteSource::fail(const std::string& message) const { throw Error(name_, offset_, 0, message); }

namespace {

// The descriptor that /dev/stdout, /dev/stderr, /dev/fd/N or /proc/self/fd/N names, if open.
std::optional<int> inherited_fd(const std::string& path) {
    int fd = -1;
    if (path == "/dev/stdout")
        fd = 1;
    else if (path == "/dev/stderr")
        fd = 2;
    else
        for (std::string_view dir : {"/dev/fd/", "/proc/self/fd/"})
            if (path.starts_with(dir) && path.size() > dir.size() && path.size() - dir.size() <= 9 &&
                path.find_first_not_of("0123456789", dir.size()) == std::string::npos)
                fd = std::stoi(path.substr(dir.size()));
    if (fd < 0 || ::fcntl(fd, F_GETFD) < 0) return std::nullopt;
    return fd;
}

}  // namespace

bool is_stream(const std::string& path) {
    struct stat st;
    return path == "-" || inherited_fd(path) ||
           (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode));
}

// ---------------- ByteSink ----------------

struct ByteSink::Gzip {
    z_stream zs;
    std::vector<std::byte> out = std::vector<std::byte>(size_t{1} << 18);
};

std::unique_ptr<ByteSink> ByteSink::open(const std::string& path, const SinkOptions& options) {
    std::unique_ptr<ByteSink> sink(new ByteSink());
    sink->name_ = path == "-" ? "<stdout>" : path;
    sink->buf_.reserve(kBufferBytes);
    struct stat st;
    if (path == "-") {
        sink->fd_ = 1;
    } else if (const std::optional<int> fd = inherited_fd(path)) {
        // The shell's own redirection (`>> log`, a pipe) is kept: renaming a file over the
        // link's target would truncate an appended file, and a pipe has no name to rename to.
        sink->fd_ = *fd;
    } else if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) {
        // A device, FIFO or socket is written in place, like stdout: renaming a file over it
        // would replace /dev/null or a pipe's reader's FIFO with a regular file. Opened by the
        // given name, so the kernel follows links that name no file (/proc/PID/fd/N → pipe:[…]).
        sink->fd_ = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
        if (sink->fd_ < 0) throw Error(path, "cannot open for writing: " + errno_text());
        sink->owns_fd_ = true;
    } else {
        sink->target_ = follow_symlinks(path);
        const bool exists = ::stat(sink->target_.c_str(), &st) == 0;
        if (exists && S_ISDIR(st.st_mode)) throw Error(path, "is a directory");
        sink->temp_path_ = make_temp(sink->target_ + ".tmp-XXXXXX", &sink->fd_, path);
        // A replaced file keeps its permissions; a new one gets the umask's.
        ::fchmod(sink->fd_, exists ? st.st_mode & 07777 : default_file_mode());
        sink->temp_slot_ = register_temp_path(sink->temp_path_);
    }
    if (options.gzip_level >= 0) {
        sink->gz_ = std::make_unique<Gzip>();
        std::memset(&sink->gz_->zs, 0, sizeof(z_stream));
        if (deflateInit2(&sink->gz_->zs, std::min(options.gzip_level, 9), Z_DEFLATED, 16 + MAX_WBITS, 8,
                         Z_DEFAULT_STRATEGY) != Z_OK)
            throw Error(sink->name_, "zlib deflateInit failed");
    }
    return sink;
}

ByteSink::~ByteSink() {
    if (gz_) deflateEnd(&gz_->zs);
    if (owns_fd_ && fd_ >= 0) ::close(fd_);
    if (!temp_path_.empty()) {
        if (fd_ >= 0) ::close(fd_);
        if (!committed_) ::unlink(temp_path_.c_str());
        unregister_temp_path(temp_slot_);
    }
}

void ByteSink::write_raw(const void* data, size_t n) {
    if (!gz_) {
        write_all(fd_, data, n, name_, offset_);
        return;
    }
    z_stream& zs = gz_->zs;
    zs.next_in = static_cast<Bytef*>(const_cast<void*>(data));
    zs.avail_in = static_cast<uInt>(n);
    while (zs.avail_in > 0) {
        zs.next_out = reinterpret_cast<Bytef*>(gz_->out.data());
        zs.avail_out = static_cast<uInt>(gz_->out.size());
        // Z_STREAM_ERROR (a finished stream) consumes nothing: looping on would never end.
        if (deflate(&zs, Z_NO_FLUSH) == Z_STREAM_ERROR) throw Error(name_, offset_, 0, "gzip stream error");
        write_all(fd_, gz_->out.data(), gz_->out.size() - zs.avail_out, name_, offset_);
    }
}

void ByteSink::flush_buffer() {
    if (buf_.empty()) return;
    write_raw(buf_.data(), buf_.size());
    buf_.clear();
}

void ByteSink::write(const void* data, size_t n) {
    if (written_) throw Error(name_, offset_, 0, "write after the output was finished");
    if (buf_.size() + n > kBufferBytes) {
        flush_buffer();
        if (n >= kBufferBytes) {
            write_raw(data, n);
            offset_ += n;
            return;
        }
    }
    auto* p = static_cast<const std::byte*>(data);
    buf_.insert(buf_.end(), p, p + n);
    offset_ += n;
}

bool ByteSink::patchable() const { return !gz_ && !temp_path_.empty(); }

void ByteSink::patch(uint64_t offset, const void* data, size_t n) {
    flush_buffer();
    auto* p = static_cast<const char*>(data);
    while (n > 0) {
        ssize_t put = ::pwrite(fd_, p, n, static_cast<off_t>(offset));
        if (put < 0) {
            if (errno == EINTR) continue;
            throw Error(name_, offset, 0, "write failed: " + errno_text());
        }
        p += put;
        n -= static_cast<size_t>(put);
        offset += static_cast<uint64_t>(put);
    }
}

void ByteSink::finish_writing() {
    if (committed_) throw Error(name_, offset_, 0, "the output was already finished");
    if (written_) return;
    flush_buffer();
    if (gz_) {
        z_stream& zs = gz_->zs;
        zs.avail_in = 0;
        int rc;
        do {
            zs.next_out = reinterpret_cast<Bytef*>(gz_->out.data());
            zs.avail_out = static_cast<uInt>(gz_->out.size());
            rc = deflate(&zs, Z_FINISH);
            if (rc == Z_STREAM_ERROR) throw Error(name_, offset_, 0, "gzip stream error");
            write_all(fd_, gz_->out.data(), gz_->out.size() - zs.avail_out, name_, offset_);
        } while (rc != Z_STREAM_END);
    }
    if (owns_fd_ || !temp_path_.empty()) {
        const int fd = fd_;
        fd_ = -1;
        if (::close(fd) != 0) throw Error(name_, "write failed on close: " + errno_text());
    }
    written_ = true;
}

void ByteSink::commit() {
    finish_writing();
    if (!temp_path_.empty() && ::rename(temp_path_.c_str(), target_.c_str()) != 0)
        throw Error(name_, "cannot rename " + temp_path_ + " into place: " + errno_text());
    committed_ = true;
}

// ---------------- TempFile ----------------

TempFile::TempFile(const std::string& dir, const std::string& stem) {
    std::string d = dir;
    if (d.empty()) {
        const char* env = std::getenv("TMPDIR");
        d = env && *env ? env : "/tmp";
    }
    path_ = make_temp(d + "/" + stem + "-XXXXXX", &fd_, d);
    slot_ = register_temp_path(path_);
    buf_.reserve(size_t{1} << 20);
}

TempFile::~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    ::unlink(path_.c_str());
    unregister_temp_path(slot_);
}

void TempFile::write(const void* data, size_t n) {
    if (buf_.size() + n > buf_.capacity()) flush();
    if (n >= buf_.capacity()) {
        write_all(fd_, data, n, path_, offset_);
        offset_ += n;
        return;
    }
    auto* p = static_cast<const std::byte*>(data);
    buf_.insert(buf_.end(), p, p + n);
}

void TempFile::flush() {
    if (buf_.empty()) return;
    write_all(fd_, buf_.data(), buf_.size(), path_, offset_);
    offset_ += buf_.size();
    buf_.clear();
}

void TempFile::read_at(uint64_t offset, void* dst, size_t n) {
    flush();
    read_flushed_at(offset, dst, n);
}

void TempFile::read_flushed_at(uint64_t offset, void* dst, size_t n) const {
    auto* p = static_cast<char*>(dst);
    while (n > 0) {
        ssize_t got = ::pread(fd_, p, n, static_cast<off_t>(offset));
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) throw Error(path_, offset, 0, "short read from temporary file");
        p += got;
        n -= static_cast<size_t>(got);
        offset += static_cast<uint64_t>(got);
    }
}

}  // namespace meshstream::io
