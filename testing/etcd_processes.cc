#include "testing/etcd_processes.h"

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "cluster/etcd_client.h"
#include "testing/child_process.h"

namespace motiondb::testing {
namespace {

namespace fs = std::filesystem;

// A loopback port free now (the kernel's pick, released at once: etcd binds it moments later).
int FreePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(address);
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
    port = ntohs(address.sin_port);
  }
  ::close(fd);
  return port;
}

}  // namespace

std::string EtcdProcesses::Binary() {
  for (const char* dir : {"/usr/bin", "/usr/local/bin", "/usr/sbin"}) {
    const fs::path path = fs::path(dir) / "etcd";
    if (::access(path.c_str(), X_OK) == 0) return path.string();
  }
  return "";
}

EtcdProcesses::~EtcdProcesses() {
  for (size_t member = 0; member < pids_.size(); ++member) Stop(static_cast<int>(member), false);
  std::error_code ignored;
  if (!dir_.empty()) fs::remove_all(dir_, ignored);
}

std::string EtcdProcesses::endpoints_flag() const { return absl::StrJoin(endpoints_, ","); }

bool EtcdProcesses::Start(int members, std::string* error) {
  if (Binary().empty()) {
    *error = "etcd is not installed (Debian package etcd-server)";
    return false;
  }
  const fs::path tmpfs = fs::is_directory("/dev/shm") ? "/dev/shm" : fs::temp_directory_path();
  std::string pattern = (tmpfs / "motiondb_etcd_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    *error = "cannot make a directory in " + tmpfs.string();
    return false;
  }
  dir_ = pattern;
  std::vector<std::string> named;
  for (int member = 0; member < members; ++member) {
    endpoints_.push_back(absl::StrCat("127.0.0.1:", FreePort()));
    peers_.push_back(absl::StrCat("http://127.0.0.1:", FreePort()));
    named.push_back(absl::StrCat("m", member, "=", peers_.back()));
  }
  initial_cluster_ = absl::StrJoin(named, ",");
  pids_.assign(members, -1);
  for (int member = 0; member < members; ++member) {
    if (!Launch(member, error)) return false;
  }
  return WaitUntilAnswering(endpoints_, error);
}

bool EtcdProcesses::Launch(int member, std::string* error) {
  const std::string name = absl::StrCat("m", member);
  const std::string client = "http://" + endpoints_[member];
  const std::vector<std::string> argv = {
      Binary(), "--name", name, "--data-dir", dir_ + "/" + name, "--listen-client-urls", client,
      "--advertise-client-urls", client, "--listen-peer-urls", peers_[member],
      "--initial-advertise-peer-urls", peers_[member], "--initial-cluster", initial_cluster_,
      "--initial-cluster-state", "new", "--initial-cluster-token",
      fs::path(dir_).filename().string(),
      // A leader killed is replaced within a second, not several.
      "--heartbeat-interval", "50", "--election-timeout", "500", "--logger", "zap", "--log-level",
      "warn"};
  // Appended: a restarted member's log keeps what it said before.
  const pid_t pid = SpawnChild(argv, ChildOptions{.log_path = absl::StrCat(dir_, "/", name, ".log"),
                                                  .stdout_to_log = true,
                                                  .append = true,
                                                  .max_open_files = 0});
  if (pid < 0) {
    *error = "fork failed";
    return false;
  }
  pids_[member] = pid;
  return true;
}

void EtcdProcesses::Stop(int member, bool graceful) {
  const pid_t pid = pids_[member];
  if (pid <= 0) return;
  StopChild(pid, graceful ? SIGTERM : SIGKILL, std::chrono::seconds(30));
  pids_[member] = -1;
}

bool EtcdProcesses::Restart(int member, std::string* error) {
  Stop(member, false);
  return Launch(member, error) && WaitUntilAnswering({endpoints_[member]}, error);
}

int EtcdProcesses::Leader() const {
  for (size_t member = 0; member < pids_.size(); ++member) {
    if (pids_[member] <= 0) continue;
    auto client =
        cluster::EtcdClient::Create(cluster::EtcdOptions{.endpoints = {endpoints_[member]},
                                                         .call_timeout = absl::Seconds(2),
                                                         .attempt_timeout = absl::Seconds(1)});
    if (!client.ok()) continue;
    const absl::StatusOr<cluster::MemberStatus> status = (*client)->Status();
    if (status.ok() && status->leads()) {
      return static_cast<int>(member);
    }
  }
  return -1;
}

bool EtcdProcesses::WaitUntilAnswering(const std::vector<std::string>& endpoints,
                                       std::string* error) const {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (std::chrono::steady_clock::now() < give_up) {
    // A client (a channel) a try: one that connected while etcd was starting can wait seconds
    // for its first answer.
    auto client =
        cluster::EtcdClient::Create(cluster::EtcdOptions{.endpoints = endpoints,
                                                         .call_timeout = absl::Seconds(2),
                                                         .attempt_timeout = absl::Seconds(1)});
    if ((*client)->Get("/motiondb-test-probe").ok()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  *error = "etcd did not answer within a minute:\n" + Logs();
  return false;
}

std::string EtcdProcesses::Logs() const {
  std::ostringstream text;
  for (size_t member = 0; member < pids_.size(); ++member) {
    std::ifstream in(absl::StrCat(dir_, "/m", member, ".log"));
    text << "--- etcd m" << member << "\n" << in.rdbuf();
  }
  return text.str();
}

}  // namespace motiondb::testing
