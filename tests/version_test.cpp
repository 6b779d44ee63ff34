// One version everywhere: `wul3d --version` and the installed header wul3d/version.hpp give
// CMake's project(VERSION) (WUL3D_PROJECT_VERSION, a compile definition of this test).
#include <gtest/gtest.h>

#include <string>

#include "test_support.hpp"
#include "wul3d/version.hpp"

namespace {

TEST(Version, HeaderIsTheProjectVersion) {
    EXPECT_EQ(std::string(WUL3D_VERSION), WUL3D_PROJECT_VERSION);
    EXPECT_EQ(std::to_string(WUL3D_VERSION_MAJOR) + "." + std::to_string(WUL3D_VERSION_MINOR) +
                  "." + std::to_string(WUL3D_VERSION_PATCH),
              WUL3D_PROJECT_VERSION);
}

TEST(Version, CommandPrintsTheProjectVersion) {
    const wul3d::test::CommandResult r = wul3d::test::run_cli({"--version"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, std::string("wul3d ") + WUL3D_PROJECT_VERSION + "\n");
}

}  // namespace
