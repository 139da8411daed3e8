#include "render/video.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/error.h"

extern char** environ;

namespace throng::render {

namespace {

// Spawns argv with stdin from `stdin_fd` (or /dev/null when -1) and stdout
// and stderr into `log_fd` (or /dev/null). Returns the pid or -1.
int spawn(const std::vector<std::string>& args, int stdin_fd, int log_fd, int close_fd) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (stdin_fd >= 0)
    posix_spawn_file_actions_adddup2(&actions, stdin_fd, STDIN_FILENO);
  else
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  if (log_fd >= 0) {
    posix_spawn_file_actions_adddup2(&actions, log_fd, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, log_fd, STDERR_FILENO);
  } else {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  }
  if (close_fd >= 0) posix_spawn_file_actions_addclose(&actions, close_fd);
  // The child leads a process group of its own: a terminal's Ctrl-C goes to
  // the foreground group, and must reach throng alone, which then ends the
  // run after the current frame, closes the pipe and lets the encoder finish
  // the file. An encoder that got the signal too would stop mid-stream.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, argv[0], &actions, &attr, argv.data(), environ);
  posix_spawnattr_destroy(&attr);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? static_cast<int>(pid) : -1;
}

int wait_for(int pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string tail_of(const std::string& path, std::size_t max_chars = 600) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  if (text.size() > max_chars) text = "..." + text.substr(text.size() - max_chars);
  return text.empty() ? "(no message)" : text;
}

// Writes everything or returns false (EPIPE: the reader has gone). SIGPIPE
// is blocked on this thread meanwhile and a pending one is consumed, so a
// dead ffmpeg is an error, not the end of the process.
bool write_all(int fd, const std::uint8_t* data, std::size_t bytes) {
  sigset_t pipe_set, old;
  sigemptyset(&pipe_set);
  sigaddset(&pipe_set, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_set, &old);
  bool ok = true;
  while (bytes > 0) {
    const ssize_t n = ::write(fd, data, bytes);
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      break;
    }
    data += n;
    bytes -= static_cast<std::size_t>(n);
  }
  if (!ok) {
    const timespec zero{0, 0};
    sigtimedwait(&pipe_set, nullptr, &zero);
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  return ok;
}

}  // namespace

void VideoSpec::validate() const {
  if (path.empty()) throw Error("no output path", at_field("video.path"));
  if (width < 2 || width > 8192 || width % 2 != 0)
    throw Error(fmt::format("{} must be even and within 2..8192 (H.264 in yuv420p)", width), at_field("video.width"));
  if (height < 2 || height > 8192 || height % 2 != 0)
    throw Error(fmt::format("{} must be even and within 2..8192 (H.264 in yuv420p)", height), at_field("video.height"));
  if (!(fps > 0.0 && fps <= 240.0) || !std::isfinite(fps))
    throw Error(fmt::format("{} is outside (0, 240]", fps), at_field("video.fps"));
  if (crf < 0 || crf > 51) throw Error(fmt::format("{} is outside 0..51", crf), at_field("video.crf"));
  if (ffmpeg.empty()) throw Error("no executable", at_field("video.ffmpeg"));
}

bool ffmpeg_available(const std::string& executable) {
  const int pid = spawn({executable, "-hide_banner", "-version"}, -1, -1, -1);
  return pid > 0 && wait_for(pid) == 0;
}

VideoWriter::VideoWriter(const VideoSpec& spec) : spec_(spec), file_(spec.path, OutputFile::OnFailure::KeepPartial) {
  spec.validate();
  if (!ffmpeg_available(spec.ffmpeg))
    throw Error(
        fmt::format("'{}' does not run: install ffmpeg (bash scripts/setup.sh --deps, or apt-get install ffmpeg)",
                    spec.ffmpeg),
        at_field("video.ffmpeg"));
  char log_template[] = "/tmp/throng-ffmpeg-XXXXXX";
  const int log_fd = mkstemp(log_template);
  if (log_fd < 0) throw Error("cannot create a log file for ffmpeg in /tmp", at_field("video.ffmpeg"));
  log_path_ = log_template;
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    ::close(log_fd);
    throw Error("cannot create a pipe to ffmpeg", at_field("video.ffmpeg"));
  }
  const std::vector<std::string> args = {spec.ffmpeg,
                                         "-hide_banner",
                                         "-loglevel",
                                         "error",
                                         "-nostdin",
                                         "-y",
                                         "-f",
                                         "rawvideo",
                                         "-pixel_format",
                                         "rgba",
                                         "-video_size",
                                         fmt::format("{}x{}", spec.width, spec.height),
                                         "-framerate",
                                         fmt::format("{}", spec.fps),
                                         "-i",
                                         "pipe:0",
                                         "-an",
                                         "-c:v",
                                         "libx264",
                                         "-preset",
                                         "veryfast",
                                         "-crf",
                                         fmt::format("{}", spec.crf),
                                         "-pix_fmt",
                                         "yuv420p",
                                         "-movflags",
                                         "+faststart",
                                         "-f",
                                         "mp4",
                                         file_.writing_path()};
  // "-nostdin" only stops ffmpeg reading keys; the frames come via pipe:0.
  pid_ = spawn(args, fds[0], log_fd, fds[1]);
  ::close(fds[0]);
  ::close(log_fd);
  if (pid_ < 0) {
    ::close(fds[1]);
    throw Error(fmt::format("cannot start '{}'", spec.ffmpeg), at_field("video.ffmpeg"));
  }
  pipe_ = fds[1];
}

VideoWriter::~VideoWriter() {
  if (const int code = close_stream(); code != 0)
    spdlog::error("video {}: ffmpeg failed (exit {}): {}", spec_.path, code, tail_of(log_path_));
  if (!log_path_.empty()) std::remove(log_path_.c_str());
}

void VideoWriter::fail(const std::string& what) {
  failed_ = true;
  if (pipe_ >= 0) ::close(pipe_);
  pipe_ = -1;
  const int code = pid_ > 0 ? wait_for(pid_) : -1;
  pid_ = -1;
  throw Error(fmt::format("{} (ffmpeg exit {}): {}", what, code, tail_of(log_path_)), at_field(spec_.path));
}

void VideoWriter::write(const Image& frame) {
  if (frame.width != spec_.width || frame.height != spec_.height)
    throw Error(fmt::format("frame is {}x{}, the video {}x{}", frame.width, frame.height, spec_.width, spec_.height),
                at_field(spec_.path));
  if (pipe_ < 0) throw Error("the video is already finished", at_field(spec_.path));
  if (!write_all(pipe_, frame.rgba.data(), frame.rgba.size())) fail("ffmpeg stopped reading frames");
  ++frames_;
}

int VideoWriter::close_stream() {
  if (pid_ < 0) return 0;
  ::close(pipe_);
  pipe_ = -1;
  const int code = wait_for(pid_);
  pid_ = -1;
  return code;
}

void VideoWriter::finish() {
  if (file_.committed()) return;
  if (failed_)
    throw Error(fmt::format("the video failed earlier; what was written is in {}", file_.writing_path()),
                at_field(spec_.path));
  if (const int code = close_stream(); code != 0)
    throw Error(fmt::format("ffmpeg failed (exit {}): {}", code, tail_of(log_path_)), at_field(spec_.path));
  file_.commit();
}

}  // namespace throng::render
