// Helpers for tests that run the `meshstream` binary (MESHSTREAM_BINARY): a private temp
// directory, a directory listing (to prove nothing was left behind) and a runner that captures
// the exit status and stderr.
#pragma once

#include "test_util.hpp"

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
using meshstream::test::slurp;
using meshstream::test::TempDir;

inline std::vector<std::string> listing(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

struct CliRun {
    int code;  // exit status; 128 + signal when killed
    std::string err;
};

// Runs `prefix meshstream ARGS` through /bin/sh (prefix: e.g. "ulimit -f 64;"); stderr is
// captured in a file outside `dir`, so `dir` holds exactly what the command left (and, not
// being a terminal, gets no progress bar; summaries are there unless ARGS has -q).
inline CliRun run(const std::string& args, const std::string& prefix = "") {
    char err_path[] = "/tmp/meshstream_cli_err-XXXXXX";
    int fd = ::mkstemp(err_path);
    ::close(fd);
    std::string cmd = prefix + " " + MESHSTREAM_BINARY + " " + args + " 2> " + err_path;
    int status = std::system(("exec >/dev/null; " + cmd).c_str());
    CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), slurp(err_path)};
    ::unlink(err_path);
    return r;
}

}  // namespace cli_test
