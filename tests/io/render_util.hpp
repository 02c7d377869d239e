// Rendering glTF files the way a web page shows them: tests/tools/render_gltf.mjs (three.js in
// headless Chromium), for the glTF tests and the decimation tests that write GLBs. Needs
// MESHSTREAM_NODE and MESHSTREAM_RENDER_GLTF (tests/CMakeLists.txt); a missing node, Chromium or
// three.js fails the test (tools/bootstrap.sh installs them), it is never skipped.
#pragma once

#include "web_test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <string>
#include <vector>

namespace web_test {

// The npm tools' node_modules (tools/bootstrap.sh puts them in MESHSTREAM_TOOLS_DIR).
inline std::string tools_modules_dir() {
    const char* env = std::getenv("MESHSTREAM_TOOLS_DIR");
    return std::string(env && *env ? env : MESHSTREAM_TOOLS_DIR) + "/node_modules";
}

// Renders `files` with three.js in headless Chromium (one browser for all; pictures in
// `dir`/shots) and returns the report per file: triangles, covered, saturated, distinct, mean,
// error.
inline nlohmann::json render(const TempDir& dir, const std::vector<std::string>& files) {
    std::vector<std::string> words = {MESHSTREAM_NODE, MESHSTREAM_RENDER_GLTF, dir / "shots"};
    words.insert(words.end(), files.begin(), files.end());
    words.push_back("--modules");
    words.push_back(tools_modules_dir());
    std::string command;
    for (const std::string& w : words) command.append(quote(w)).append(" ");
    command.append("2>&1");
    std::string out;
    const int status = run(command, &out);
    EXPECT_EQ(status, 0) << "render_gltf could not run (tools/bootstrap.sh installs chromium and three): " << out;
    nlohmann::json report = nlohmann::json::parse(out, nullptr, false);
    EXPECT_TRUE(report.is_array()) << out;
    if (!report.is_array() || report.size() != files.size()) return nlohmann::json::array();
    for (const nlohmann::json& r : report) EXPECT_FALSE(r.contains("error")) << r.dump();
    return report;
}

}  // namespace web_test
