// Live teach runs end to end: `vmap build` reading a network stream that the ffmpeg CLI serves on the
// loopback (bounded in time, self-stopping), with snapshots while it runs, and SIGINT with and without
// --until-interrupted. Skipped without ../shared or without the ffmpeg CLI.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/map/map_io.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"
#include "vmap/testing/synthetic_scene.h"

extern char** environ;

namespace vmap {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

bool HaveFfmpeg() { return std::system("command -v ffmpeg > /dev/null 2>&1") == 0; }

#define REQUIRE_SHARED_AND_FFMPEG()                                             \
  if (testing::SharedDir().empty()) GTEST_SKIP() << "../shared is not present"; \
  if (!HaveFfmpeg()) GTEST_SKIP() << "the ffmpeg CLI is not installed (scripts/install-deps.sh)"

// A child process with its output in `log`, ended (SIGKILL) if a test leaves it running.
class Child {
 public:
  Child(const std::vector<std::string>& arguments, const fs::path& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    // The child starts with SIGINT handled as from a terminal, whatever this runner inherited.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t defaults, none;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigemptyset(&none);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setsigmask(&attributes, &none);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    std::vector<char*> argv;
    for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    if (posix_spawnp(&pid_, argv[0], &actions, &attributes, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
  }
  ~Child() {
    if (running()) {
      kill(pid_, SIGKILL);
      Wait(10);
    }
  }

  bool started() const { return pid_ > 0; }
  bool running() {
    if (pid_ <= 0 || status_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) status_ = status;
    return !status_;
  }
  void Signal(int signal_number) const { kill(pid_, signal_number); }
  // The exit code (128 + signal when killed), or -1 when it still runs after `seconds` (a deadline, so that a
  // failure cannot hang the test; not a timing assertion).
  int Wait(double seconds) {
    const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    while (running() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (!status_) return -1;
    return WIFEXITED(*status_) ? WEXITSTATUS(*status_) : 128 + WTERMSIG(*status_);
  }

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

// A TCP port of the loopback that nothing uses now.
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return ntohs(address.sin_port);
}

// Whether something listens on 127.0.0.1:port (from /proc/net/tcp: local address, state 0A = LISTEN).
bool Listening(int port) {
  std::ifstream table("/proc/net/tcp");
  const std::string local = fmt::format("0100007F:{:04X}", port);
  std::string line;
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot, address, remote, state;
    fields >> slot >> address >> remote >> state;
    if (address == local && state == "0A") return true;
  }
  return false;
}

template <typename Condition>
bool WaitFor(Condition condition, double seconds) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return condition();
}

std::string Read(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// vmap listens on the loopback (an FFmpeg tcp:// URL with listen=1) and ffmpeg sends it lab_floor.mp4 at its
// own frame rate for `seconds`, as MPEG-TS with a key frame every 10 frames, then closes the connection.
struct LiveRun {
  testing::ScopedTempDir tmp;
  int port = FreePort();
  fs::path output = tmp.path() / "live_map";
  std::unique_ptr<Child> vmap;
  std::unique_ptr<Child> sender;

  // `frame_rate` > 0: the video resampled to that many frames a second (a slow camera, a thin link).
  void Start(const std::vector<std::string>& flags, double seconds, double frame_rate = 0.0) {
    std::vector<std::string> arguments = {testing::VmapBinary().string(), "build",
                                          fmt::format("tcp://127.0.0.1:{}?listen=1", port), "-o", output.string()};
    arguments.insert(arguments.end(), flags.begin(), flags.end());
    vmap = std::make_unique<Child>(arguments, tmp.path() / "vmap.log");
    ASSERT_TRUE(vmap->started());
    ASSERT_TRUE(WaitFor([&] { return Listening(port) || !vmap->running(); }, 20)) << Read(tmp.path() / "vmap.log");
    ASSERT_TRUE(vmap->running()) << Read(tmp.path() / "vmap.log");
    const std::string video = (fs::path(testing::SharedDir()) / "data/lab_floor/lab_floor.mp4").string();
    std::vector<std::string> command = {
        "ffmpeg", "-nostdin", "-loglevel", "error", "-re", "-i", video, "-t", fmt::format("{}", seconds), "-an"};
    if (frame_rate > 0) command.insert(command.end(), {"-vf", fmt::format("fps={}", frame_rate)});
    command.insert(command.end(), {"-c:v", "mpeg2video", "-q:v", "4", "-g", "10", "-f", "mpegts",
                                   fmt::format("tcp://127.0.0.1:{}", port)});
    sender = std::make_unique<Child>(command, tmp.path() / "ffmpeg.log");
    ASSERT_TRUE(sender->started());
  }
  std::string log() { return Read(tmp.path() / "vmap.log") + "\nffmpeg: " + Read(tmp.path() / "ffmpeg.log"); }
  // Only the map (and the logs) beside it: no temporary left behind.
  std::vector<std::string> Entries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(tmp.path())) {
      const std::string name = entry.path().filename().string();
      if (name != "vmap.log" && name != "ffmpeg.log") names.push_back(name);
    }
    return names;
  }
};

}  // namespace

TEST(LiveCli, SnapshotsAreReadableMapsWhileTheStreamRunsAndTheEndFinishesTheMap) {
  REQUIRE_SHARED_AND_FFMPEG();
  LiveRun run;
  run.Start({"--snapshot-every", "0.5"}, 6);
  // A snapshot appears while vmap still reads the stream.
  ASSERT_TRUE(WaitFor([&] { return fs::exists(run.output / kMapFileName) || !run.vmap->running(); }, 60)) << run.log();
  ASSERT_TRUE(run.vmap->running()) << "the stream lasts 6 s: a snapshot was expected before its end\n" << run.log();
  const VisualMap snapshot = ReadMap(run.output);
  EXPECT_GE(snapshot.key_images.size(), 1u);
  ASSERT_TRUE(snapshot.coverage);
  EXPECT_EQ(snapshot.coverage->end, CoverageEnd::kSnapshot);
  EXPECT_EQ(snapshot.coverage->num_frames, snapshot.num_frames);

  // The sender stops by itself; the closed connection ends the input and the map is finished.
  ASSERT_EQ(run.vmap->Wait(120), 0) << run.log();
  EXPECT_EQ(run.sender->Wait(30), 0) << run.log();
  const VisualMap map = ReadMap(run.output);
  EXPECT_GT(map.num_frames, snapshot.num_frames);
  EXPECT_GE(map.key_images.size(), 2u);
  ASSERT_TRUE(map.coverage) << "a stream has no known length: the map says what it covers";
  EXPECT_EQ(map.coverage->end, CoverageEnd::kInputEnded);
  EXPECT_EQ(map.coverage->first_source_index, 0);
  EXPECT_EQ(map.coverage->last_source_index, map.num_frames - 1);
  EXPECT_EQ(run.Entries(), std::vector<std::string>{"live_map"});
}

// A slow stream (2 frames/s) that sends all along is not taken for one that stopped: opening it probes more of it than
// it sends within --stream-timeout, and every frame it sent is in the map (before: 2 of 20, and the sender cut off).
TEST(LiveCli, ASlowStreamIsReadToItsEnd) {
  REQUIRE_SHARED_AND_FFMPEG();
  LiveRun run;
  run.Start({"--stream-timeout", "2"}, 10, 2);
  ASSERT_EQ(run.vmap->Wait(120), 0) << run.log();
  EXPECT_EQ(run.sender->Wait(30), 0) << "the sender was cut off\n" << run.log();
  const VisualMap map = ReadMap(run.output);
  EXPECT_GE(map.num_frames, 19) << "of the 20 sent\n" << run.log();
}

TEST(LiveCli, UntilInterruptedSigintEndsTheInputAndTheMapIsFinishedFromWhatWasSeen) {
  REQUIRE_SHARED_AND_FFMPEG();
  LiveRun run;
  run.Start({"--until-interrupted", "--snapshot-every", "0.5"}, 60);
  // Frames have been processed once a snapshot exists; then the user presses Ctrl-C.
  ASSERT_TRUE(WaitFor([&] { return fs::exists(run.output / kMapFileName) || !run.vmap->running(); }, 60)) << run.log();
  ASSERT_TRUE(run.vmap->running()) << run.log();
  run.vmap->Signal(SIGINT);
  ASSERT_EQ(run.vmap->Wait(120), 0) << run.log();
  run.sender->Signal(SIGTERM);  // still sending: its 60 s are not over
  run.sender->Wait(30);
  const VisualMap map = ReadMap(run.output);
  EXPECT_GE(map.num_frames, 1);
  ASSERT_TRUE(map.coverage);
  EXPECT_EQ(map.coverage->end, CoverageEnd::kInterrupted);
  EXPECT_EQ(map.coverage->num_frames, map.num_frames);
  EXPECT_EQ(map.coverage->last_source_index, map.num_frames - 1);
  EXPECT_EQ(map.key_images.back().frame_index, map.num_frames - 1) << "the last frame seen is the final key image";
  const auto doc = nlohmann::json::parse(Read(run.output / kMapFileName));
  EXPECT_EQ(doc["coverage"]["end"], "interrupted");
  EXPECT_EQ(run.Entries(), std::vector<std::string>{"live_map"});
}

TEST(LiveCli, WithoutUntilInterruptedSigintAbortsAndLeavesNothingBehind) {
  REQUIRE_SHARED_AND_FFMPEG();
  LiveRun run;
  run.Start({}, 60);
  // Let frames flow for a moment (what is being built must not survive the abort).
  std::this_thread::sleep_for(std::chrono::seconds(2));
  ASSERT_TRUE(run.vmap->running()) << run.log();
  run.vmap->Signal(SIGINT);
  EXPECT_EQ(run.vmap->Wait(60), 128 + SIGINT) << run.log();
  run.sender->Signal(SIGTERM);
  run.sender->Wait(30);
  EXPECT_TRUE(run.Entries().empty()) << run.log();
}

TEST(LiveCli, AMissingCameraIsAnInputErrorNamingTheDeviceAndTheFix) {
  std::string out;
  EXPECT_EQ(testing::RunVmap("build /dev/video97 -o /tmp/never_written_vmap_map", &out), 2) << out;
  EXPECT_NE(out.find("camera '/dev/video97' does not exist"), std::string::npos) << out;
  EXPECT_NE(out.find("ls /dev/video*"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists("/tmp/never_written_vmap_map"));
}

TEST(LiveCli, AStreamThatNeverStartsIsAnInputError) {
  // Nothing listens on this port: the connection is refused at once.
  std::string out;
  testing::ScopedTempDir tmp;
  EXPECT_EQ(
      testing::RunVmap(fmt::format("build tcp://127.0.0.1:{} -o '{}'", FreePort(), (tmp.path() / "m").string()), &out),
      2)
      << out;
  EXPECT_NE(out.find("cannot open stream 'tcp://127.0.0.1:"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp.path() / "m"));
}

// A UDP stream waits for a sender; --stream-timeout says for how long (the message names the wait it made).
TEST(LiveCli, StreamTimeoutBoundsTheWaitForAStreamThatSendsNothing) {
  std::string out;
  testing::ScopedTempDir tmp;
  EXPECT_EQ(testing::RunVmap(fmt::format("build udp://127.0.0.1:{} --stream-timeout 1 -o '{}'", FreePort(),
                                         (tmp.path() / "m").string()),
                             &out),
            2)
      << out;
  EXPECT_NE(out.find("no video FFmpeg can decode arrived within 1 s"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp.path() / "m"));
}

}  // namespace vmap
