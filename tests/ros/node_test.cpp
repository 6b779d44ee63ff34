// wul3d_ros against a real roscore on a free port of 127.0.0.1, fed by wul3d_test_publisher
// (tests/ros/frame_publisher.cpp). Every process started here is in its own process group and
// is ended with it (SIGINT, then SIGKILL after 5 s); every wait is bounded.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "test_support.hpp"
#include "wul3d/io.hpp"

namespace fs = std::filesystem;

namespace {

/// A child process in its own group, output to a log file; ended with its group.
class Child {
public:
    Child(const std::vector<std::string>& args, const fs::path& log) {
        pid_ = ::fork();
        if (pid_ < 0) throw std::runtime_error("fork failed");
        if (pid_ == 0) {
            ::setpgid(0, 0);
            const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            ::dup2(fd, 1);
            ::dup2(fd, 2);
            const int in = ::open("/dev/null", O_RDONLY);
            ::dup2(in, 0);
            std::vector<char*> argv;
            for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
            argv.push_back(nullptr);
            ::execvp(argv[0], argv.data());
            ::_exit(127);
        }
        ::setpgid(pid_, pid_);
    }
    ~Child() { stop(); }
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    /// Still running?
    bool alive() {
        if (done_) return false;
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) {
            done_ = true;
            status_ = status;
        }
        return !done_;
    }
    /// SIGINT to the group (roscore's children too), SIGKILL after 5 s; the exit status.
    int stop() {
        if (!done_) {
            ::kill(-pid_, SIGINT);
            for (int i = 0; i < 100 && alive(); ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(50));
            if (alive()) {
                ::kill(-pid_, SIGKILL);
                ::waitpid(pid_, &status_, 0);
                done_ = true;
            }
        }
        ::kill(-pid_, SIGKILL);  // whatever of the group is left (rosmaster, rosout)
        return status_;
    }

private:
    pid_t pid_ = -1;
    bool done_ = false;
    int status_ = 0;
};

int free_port() {
    const int s = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t n = sizeof a;
    ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &n);
    ::close(s);
    return ntohs(a.sin_port);
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

/// roscore on a free port of 127.0.0.1, its logs in `dir`; the environment points there.
/// Ready when its log says the core service started. A port found free can be taken before
/// roscore binds it (the ROS processes of a test running beside this one open ephemeral
/// ports), and roscore then exits: up to three tries, each on a new port, each waiting at
/// most 30 s.
class RosCore {
public:
    explicit RosCore(const fs::path& dir) {
        ::setenv("ROS_IP", "127.0.0.1", 1);
        ::setenv("ROS_HOSTNAME", "127.0.0.1", 1);
        ::setenv("ROS_HOME", dir.c_str(), 1);
        ::setenv("ROS_LOG_DIR", dir.c_str(), 1);
        for (int attempt = 0; attempt < 3; ++attempt) {
            port_ = free_port();
            const std::string uri = "http://127.0.0.1:" + std::to_string(port_);
            ::setenv("ROS_MASTER_URI", uri.c_str(), 1);
            const fs::path log = dir / ("roscore" + std::to_string(attempt) + ".log");
            core_.emplace(std::vector<std::string>{"roscore", "-p", std::to_string(port_)}, log);
            for (int i = 0; i < 300 && core_->alive(); ++i) {
                if (read_text(log).find("started core service") != std::string::npos) return;
                std::this_thread::sleep_for(std::chrono::milliseconds(100));
            }
            core_.reset();  // ended with its group
        }
        throw std::runtime_error("roscore did not start in three tries (logs in " + dir.string() + ")");
    }
    int port() const { return port_; }

private:
    int port_ = 0;
    std::optional<Child> core_;
};

fs::path tabletop() { return wul3d::test::sample_dir() / "uois_tabletop"; }

wul3d::test::CommandResult publish(const fs::path& out, const std::vector<std::string>& mode) {
    std::vector<std::string> args = {"timeout", "180", WUL3D_TEST_PUBLISHER, tabletop().string(),
                                     out.string()};
    args.insert(args.end(), mode.begin(), mode.end());
    return wul3d::test::run_command(args);
}

/// Sorted frame folder names of a `wul3d run` output.
std::vector<std::string> run_frames(const fs::path& out) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(out))
        if (e.is_directory()) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace

TEST(RosNode, LabelsEqualRunsObjectsPngPixelForPixel) {
    wul3d::test::TempDir dir;
    const auto run = wul3d::test::run_cli(
        {"run", tabletop().string(), "--out", (dir / "run").string(), "--quiet"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto names = run_frames(dir / "run");

    RosCore core(dir.path());
    Child node({WUL3D_ROS_NODE_BIN}, dir / "node.log");
    fs::create_directories(dir / "labels");
    const auto r = publish(dir / "labels", {"lockstep"});
    ASSERT_EQ(r.exit_code, 0) << r.err << read_text(dir / "node.log");
    std::printf("lockstep: %s", r.out.substr(r.out.find("sent ")).c_str());
    ASSERT_EQ(names.size(), 4u);
    for (std::size_t i = 0; i < names.size(); ++i) {
        const auto want = wul3d::read_label_png((dir / "run" / names[i] / "objects.png").string());
        const auto got = wul3d::read_label_png((dir / "labels" / (std::to_string(i) + ".png")).string());
        EXPECT_EQ(got.width, want.width);
        EXPECT_EQ(got.height, want.height);
        EXPECT_TRUE(got.labels == want.labels) << "frame " << names[i];
    }
    EXPECT_TRUE(node.alive()) << read_text(dir / "node.log");
}

TEST(RosNode, UnalignedDepthWithACalibration_LabelsEqualRunWithThatCalibration) {
    wul3d::test::TempDir dir;
    // A two-camera calibration of the shipped frames' camera (both cameras one, 1 cm apart):
    // the node registers each frame first, as `wul3d run --calibration` does.
    auto source = wul3d::open_source(tabletop().string(), {});
    wul3d::SourceItem item;
    source->read(0, item);
    wul3d::StereoCalibration calib;
    calib.depth = calib.color = item.frame.intrinsics;
    calib.translation_m = {0.01, 0, 0};
    wul3d::write_calibration_json((dir / "calib.json").string(), calib);
    const auto run = wul3d::test::run_cli({"run", tabletop().string(), "--calibration",
                                           (dir / "calib.json").string(), "--out",
                                           (dir / "run").string(), "--quiet"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto names = run_frames(dir / "run");

    RosCore core(dir.path());
    Child node({WUL3D_ROS_NODE_BIN, "_calibration:=" + (dir / "calib.json").string()},
               dir / "node.log");
    fs::create_directories(dir / "labels");
    const auto r = publish(dir / "labels", {"lockstep"});
    ASSERT_EQ(r.exit_code, 0) << r.err << read_text(dir / "node.log");
    ASSERT_EQ(names.size(), 4u);
    for (std::size_t i = 0; i < names.size(); ++i) {
        const auto want = wul3d::read_label_png((dir / "run" / names[i] / "objects.png").string());
        const auto got = wul3d::read_label_png((dir / "labels" / (std::to_string(i) + ".png")).string());
        EXPECT_EQ(got.width, want.width);
        EXPECT_TRUE(got.labels == want.labels) << "frame " << names[i];
    }
}

TEST(RosNode, SurvivesMalformedMessagesAndThePublisherRestarting) {
    wul3d::test::TempDir dir;
    RosCore core(dir.path());
    Child node({WUL3D_ROS_NODE_BIN}, dir / "node.log");
    const auto bad = publish(dir.path(), {"malformed"});
    EXPECT_EQ(bad.exit_code, 0) << bad.err << read_text(dir / "node.log");
    ASSERT_TRUE(node.alive()) << read_text(dir / "node.log");
    // A new publisher, as after a camera driver's restart: the node serves it too.
    fs::create_directories(dir / "again");
    const auto again = publish(dir / "again", {"lockstep"});
    EXPECT_EQ(again.exit_code, 0) << again.err << read_text(dir / "node.log");
    EXPECT_TRUE(node.alive());
    node.stop();
    const std::string log = read_text(dir / "node.log");
    EXPECT_NE(log.find("yuv422"), std::string::npos) << log;         // the wrong encoding
    EXPECT_NE(log.find("bytes but has"), std::string::npos) << log;  // the size mismatch
}

TEST(RosNode, At30FpsDropsFramesRatherThanQueueing) {
    wul3d::test::TempDir dir;
    RosCore core(dir.path());
    Child node({WUL3D_ROS_NODE_BIN}, dir / "node.log");
    const auto r = publish(dir.path(), {"stream", "30", "90"});
    ASSERT_EQ(r.exit_code, 0) << r.err << read_text(dir / "node.log");
    unsigned long sent = 0, received = 0;
    const auto line = r.out.find("sent ");  // after rosconsole's own lines
    ASSERT_NE(line, std::string::npos) << r.out;
    ASSERT_EQ(std::sscanf(r.out.c_str() + line, "sent %lu received %lu", &sent, &received), 2) << r.out;
    std::printf("30 FPS: %s", r.out.c_str() + line);
    EXPECT_EQ(sent, 90u);
    EXPECT_GT(received, 0u);
    EXPECT_LE(received, sent);
    node.stop();
    const std::string log = read_text(dir / "node.log");
    // Whatever it dropped, it says so (its last line counts them).
    const auto last = log.rfind("wul3d: ");
    std::printf("node: %s\n", last == std::string::npos ? "(no summary)" : log.substr(last).c_str());
    if (received < sent) {
        EXPECT_NE(log.find("dropped"), std::string::npos) << log;
    }
}

TEST(RosNode, BadParameter_OneLineAndExit2) {
    wul3d::test::TempDir dir;
    RosCore core(dir.path());
    // `wul3d run --k 0`'s check, through the ROS parameter ~k.
    // The library's check names the ROS parameter, as the command names its flag.
    auto r = wul3d::test::run_command({"timeout", "60", WUL3D_ROS_NODE_BIN, "_k:=0"});
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE((r.out + r.err).find("wul3d: ~k 0: must be in [1, 65535]"), std::string::npos)
        << r.out << r.err;
    // Every row of the table is a ROS parameter: ~object_psi too (~k reset: the parameter
    // server keeps the last run's).
    r = wul3d::test::run_command(
        {"timeout", "60", WUL3D_ROS_NODE_BIN, "_k:=7", "_object_psi:=2.0"});
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE((r.out + r.err).find("wul3d: ~object_psi 2: must be in (0, 1]"), std::string::npos)
        << r.out << r.err;
}
