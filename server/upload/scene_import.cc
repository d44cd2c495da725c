#include "server/upload/scene_import.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

extern char** environ;

namespace motiondb::server {
namespace {

// How often a running import looks at its stop function and its time.
constexpr int kPollMs = 50;
// What is kept of the importer's own error output, for an error that needs it.
constexpr size_t kMaxErrorOutput = 4096;

class Descriptor {
 public:
  explicit Descriptor(int fd = -1) : fd_(fd) {}
  Descriptor(Descriptor&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  Descriptor& operator=(Descriptor&& other) noexcept {
    Close();
    fd_ = std::exchange(other.fd_, -1);
    return *this;
  }
  ~Descriptor() { Close(); }
  int get() const { return fd_; }
  void Close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

absl::Status ErrnoStatus(absl::string_view what) {
  return absl::UnavailableError(absl::StrCat(what, ": ", std::strerror(errno)));
}

// The parent's and the child's ends of a channel. The file goes over a socket, which can be
// written without SIGPIPE when the importer has gone; its answers come back over pipes.
struct Channel {
  Descriptor parent;
  Descriptor child;
};

absl::StatusOr<Channel> SocketChannel() {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0) {
    return ErrnoStatus("socketpair");
  }
  return Channel{Descriptor(fds[0]), Descriptor(fds[1])};
}

absl::StatusOr<Channel> PipeChannel() {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return ErrnoStatus("pipe");
  return Channel{Descriptor(fds[0]), Descriptor(fds[1])};
}

// The importer's process: killed and reaped when it is let go of before it ended.
class Child {
 public:
  explicit Child(pid_t pid) : pid_(pid) {}
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      Wait();
    }
  }
  // Its wait status once it ended.
  int Wait() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    return status;
  }

 private:
  pid_t pid_;
};

struct ImporterOutput {
  std::string out;
  std::string err;
  int wait_status = 0;
};

// Sends `bytes` to the importer and reads what it writes, until it ends.
absl::StatusOr<ImporterOutput> RunImporter(const std::vector<std::string>& args,
                                           absl::string_view bytes, const UploadLimits& limits,
                                           const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(Channel in, SocketChannel());
  MOTIONDB_ASSIGN_OR_RETURN(Channel out, PipeChannel());
  MOTIONDB_ASSIGN_OR_RETURN(Channel err, PipeChannel());
  // The child's ends: its in is the socket's second end; its out and err are the pipes' write
  // ends, which PipeChannel names `child`.
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in.child.get(), STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out.child.get(), STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, err.child.get(), STDERR_FILENO);
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    return absl::UnavailableError(
        absl::StrCat("cannot start the importer ", args[0], ": ", std::strerror(spawned)));
  }
  Child child(pid);
  in.child.Close();
  out.child.Close();
  err.child.Close();
  for (int fd : {in.parent.get(), out.parent.get(), err.parent.get()}) {
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
  }

  const auto deadline = std::chrono::steady_clock::now() + limits.max_import_time;
  ImporterOutput output;
  size_t sent = 0;
  if (bytes.empty()) in.parent.Close();
  while (out.parent.get() >= 0 || err.parent.get() >= 0) {
    if (should_stop && should_stop()) {
      return absl::CancelledError("reading the file was stopped by its caller");
    }
    if (std::chrono::steady_clock::now() > deadline) {
      return absl::DeadlineExceededError(absl::StrCat(
          "reading the file took over ",
          std::chrono::duration_cast<std::chrono::seconds>(limits.max_import_time).count(),
          " s; it was stopped"));
    }
    pollfd fds[3] = {{in.parent.get(), POLLOUT, 0},
                     {out.parent.get(), POLLIN, 0},
                     {err.parent.get(), POLLIN, 0}};
    if (::poll(fds, 3, kPollMs) < 0 && errno != EINTR) return ErrnoStatus("poll");
    if (fds[0].revents != 0) {
      const ssize_t n = ::send(in.parent.get(), bytes.data() + sent, bytes.size() - sent,
                               MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) sent += static_cast<size_t>(n);
      // Sent whole, or the importer stopped reading (it says why on its out).
      if (sent == bytes.size() || (n < 0 && errno != EAGAIN && errno != EINTR)) {
        in.parent.Close();
      }
    }
    for (int i : {1, 2}) {
      if (fds[i].revents == 0) continue;
      Descriptor& fd = i == 1 ? out.parent : err.parent;
      std::string& text = i == 1 ? output.out : output.err;
      char buffer[1 << 16];
      const ssize_t n = ::read(fd.get(), buffer, sizeof(buffer));
      if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
        fd.Close();
        continue;
      }
      if (n < 0) continue;
      text.append(buffer, static_cast<size_t>(n));
      if (i == 2 && text.size() > kMaxErrorOutput) text.erase(0, text.size() - kMaxErrorOutput);
      if (i == 1 && static_cast<int64_t>(text.size()) > limits.max_bvh_bytes) {
        return absl::ResourceExhaustedError(absl::StrCat("the file's takes make over ",
                                                         limits.max_bvh_bytes,
                                                         " bytes of motion (--max-bvh-mb)"));
      }
    }
  }
  output.wait_status = child.Wait();
  return output;
}

// The importer's answer: its facts, warnings and takes, each take's BVH parsed here.
absl::StatusOr<UploadedFile> ParseAnswer(absl::string_view out, absl::string_view err,
                                         MotionFileFormat format, const UploadLimits& limits) {
  UploadedFile file;
  file.format = format;
  bool ended = false;
  while (!out.empty() && !ended) {
    const size_t newline = out.find('\n');
    if (newline == absl::string_view::npos) break;
    const absl::string_view line = out.substr(0, newline);
    out.remove_prefix(newline + 1);
    absl::string_view rest = line;
    if (line == "end") {
      ended = true;
    } else if (absl::ConsumePrefix(&rest, "error ")) {
      const std::pair<absl::string_view, absl::string_view> parts =
          absl::StrSplit(rest, absl::MaxSplits(' ', 1));
      int code = 0;
      if (!absl::SimpleAtoi(parts.first, &code) || code <= 0 || code > 16) {
        code = static_cast<int>(absl::StatusCode::kInvalidArgument);
      }
      return absl::Status(static_cast<absl::StatusCode>(code), parts.second);
    } else if (absl::ConsumePrefix(&rest, "warning ")) {
      file.warnings.emplace_back(rest);
    } else if (absl::ConsumePrefix(&rest, "fact unit_m ")) {
      if (!absl::SimpleAtod(rest, &file.unit_m)) file.unit_m = 0;
    } else if (absl::ConsumePrefix(&rest, "fact up_axis ") && rest.size() == 1) {
      file.up_axis = rest[0];
    } else if (absl::ConsumePrefix(&rest, "fact generator ")) {
      file.generator = std::string(rest);
    } else if (absl::ConsumePrefix(&rest, "take ")) {
      const std::pair<absl::string_view, absl::string_view> sizes =
          absl::StrSplit(rest, absl::MaxSplits(' ', 1));
      size_t name_size = 0;
      size_t bvh_size = 0;
      if (!absl::SimpleAtoi(sizes.first, &name_size) ||
          !absl::SimpleAtoi(sizes.second, &bvh_size) || name_size + bvh_size > out.size()) {
        break;
      }
      std::string name(out.substr(0, name_size));
      MOTIONDB_ASSIGN_OR_RETURN(
          BvhReadResult read,
          Prefixed(absl::StrCat("take '", name, "'"),
                   ReadBvh(out.substr(name_size, bvh_size), UploadReadOptions(limits))));
      out.remove_prefix(name_size + bvh_size);
      file.takes.push_back({std::move(name), std::move(read.clip)});
    }
  }
  if (!ended || file.takes.empty()) {
    return absl::InternalError(
        absl::StrCat("the importer's answer was cut short", err.empty() ? "" : "; it said: ", err));
  }
  return file;
}

}  // namespace

std::string SceneImporterPath(const std::string& configured) {
  if (!configured.empty()) return configured;
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path beside = self.parent_path() / "motiondb-scene-import";
    if (std::filesystem::exists(beside, error)) return beside.string();
  }
  return MOTIONDB_SCENE_IMPORTER_BUILD_PATH;
}

absl::StatusOr<UploadedFile> ImportScene(absl::string_view bytes, MotionFileFormat format,
                                         const UploadLimits& limits,
                                         const std::function<bool()>& should_stop) {
  const std::vector<std::string> args = {
      SceneImporterPath(limits.scene_importer),
      "--format",
      std::string(MotionFileFormatName(format)),
      "--max-clip-bytes",
      absl::StrCat(limits.max_buffered_bytes),
      "--max-memory-mb",
      absl::StrCat(std::max<int64_t>(1, limits.max_import_bytes >> 20)),
  };
  MOTIONDB_ASSIGN_OR_RETURN(ImporterOutput output, RunImporter(args, bytes, limits, should_stop));
  if (WIFSIGNALED(output.wait_status)) {
    const int signal = WTERMSIG(output.wait_status);
    return absl::InvalidArgumentError(
        absl::StrCat("the ", MotionFileFormatName(format), " reader failed on this file (signal ",
                     signal, ", ", strsignal(signal), "); it is probably corrupt"));
  }
  return ParseAnswer(output.out, output.err, format, limits);
}

}  // namespace motiondb::server
