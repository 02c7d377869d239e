// Helpers for tests that run the `meshstream` binary (MESHSTREAM_BINARY): a private temp
// directory, a directory listing (to prove nothing was left behind) and a runner that captures
// the exit status and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace cli_test {

namespace fs = std::filesystem;

struct TempDir {
    fs::path path;
    TempDir() {
        std::string pattern = (fs::temp_directory_path() / "meshstream_cli-XXXXXX").string();
        path = ::mkdtemp(pattern.data());
    }
    ~TempDir() { fs::remove_all(path); }
    std::string operator/(const std::string& name) const { return (path / name).string(); }
};

inline std::vector<std::string> listing(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

inline std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CliRun {
    int code;  // exit status; 128 + signal when killed
    std::string err;
};

// Runs `prefix meshstream -q ARGS` through /bin/sh (prefix: e.g. "ulimit -f 64;"); stderr is
// captured in a file outside `dir`, so `dir` holds exactly what the command left.
inline CliRun run(const std::string& args, const std::string& prefix = "") {
    char err_path[] = "/tmp/meshstream_cli_err-XXXXXX";
    int fd = ::mkstemp(err_path);
    ::close(fd);
    std::string cmd = prefix + " " + MESHSTREAM_BINARY + " -q " + args + " 2> " + err_path;
    int status = std::system(("exec >/dev/null; " + cmd).c_str());
    CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), slurp(err_path)};
    ::unlink(err_path);
    return r;
}

}  // namespace cli_test
