// `wul3d view` when the build found no GLFW 3, OpenGL or Dear ImGui (see cmake/Viewer.cmake):
// the command exists, says why it cannot run, and exits 2.
#include "cli.hpp"
#include "wul3d/error.hpp"

namespace wul3d::cli {

void add_view_command(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("view", "Watch a recording live (not in this build)");
    cmd->allow_extras();
    cmd->callback([]() {
        throw InputError("built without viewer support (needs GLFW 3, OpenGL and Dear ImGui: "
                         "libglfw3-dev libgl-dev libimgui-dev)");
    });
}

}  // namespace wul3d::cli
