// open_bag (wul3d/bag.hpp) in a build without librosbag: bags are refused with one line.
#include "wul3d/bag.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

bool bag_support() { return false; }

std::unique_ptr<FrameSource> open_bag(const std::string& path, const SourceOptions&) {
    throw InputError(path + ": this wul3d was built without ROS bag support (librosbag-dev "
                            "was not found, or WUL3D_WITH_ROS=OFF; scripts/install-deps.sh installs it)");
}

}  // namespace wul3d
