#include "testing/server_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "grpc/health/v1/health.grpc.pb.h"

namespace motiondb::testing {
namespace {

// 128 + signal for a signalled child, as a shell reports it.
int ExitCode(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

}  // namespace

std::string ServerPath() {
  const char* given = std::getenv("MOTIONDB_SERVER_BIN");
  return given != nullptr && *given != '\0' ? given : MOTIONDB_SERVER_PATH;
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  if (!log_path_.empty()) std::filesystem::remove(log_path_);
}

bool ServerProcess::Start(const std::vector<std::string>& args, std::string* error,
                          std::chrono::seconds timeout) {
  static std::atomic<int> starts{0};
  log_path_ =
      (std::filesystem::temp_directory_path() /
       ("motiondb_server_" + std::to_string(::getpid()) + "_" + std::to_string(starts++) + ".log"))
          .string();
  std::vector<std::string> argv_strings = {ServerPath(), "--listen", "127.0.0.1:0"};
  const bool http_given = std::find(args.begin(), args.end(), "--http") != args.end();
  if (!http_given) argv_strings.insert(argv_strings.end(), {"--http", "127.0.0.1:0"});
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  const auto http = std::find(argv_strings.begin(), argv_strings.end(), "--http");
  const bool http_off = http + 1 < argv_strings.end() && http[1] == "off";
  std::vector<char*> argv;
  for (std::string& arg : argv_strings) argv.push_back(arg.data());
  argv.push_back(nullptr);

  pid_ = ::fork();
  if (pid_ == 0) {
    const int log = ::open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDWR);
    if (log < 0 || null < 0) ::_exit(126);
    ::dup2(null, STDIN_FILENO);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(log, STDERR_FILENO);
    if (max_open_files_ > 0) {
      const rlimit files{static_cast<rlim_t>(max_open_files_),
                         static_cast<rlim_t>(max_open_files_)};
      if (::setrlimit(RLIMIT_NOFILE, &files) != 0) ::_exit(125);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (pid_ < 0) {
    *error = "fork failed";
    return false;
  }
  const std::regex port_line("\\(port ([0-9]+)\\)");
  const std::regex http_port_line("\\(http port ([0-9]+)\\)");
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < give_up) {
    std::smatch match, http_match;
    const std::string log = Log();
    if (std::regex_search(log, match, port_line) &&
        (http_off || std::regex_search(log, http_match, http_port_line))) {
      port_ = std::stoi(match[1]);
      http_port_ = http_off ? 0 : std::stoi(http_match[1]);
      return true;
    }
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      *error = "the server exited with code " + std::to_string(ExitCode(status)) + ":\n" + Log();
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  *error = "the server did not report its port in time:\n" + Log();
  return false;
}

int ServerProcess::Stop(int signal, std::chrono::seconds timeout) {
  if (pid_ <= 0) return -1;
  ::kill(pid_, signal);
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < give_up) {
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return ExitCode(status);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid_, SIGKILL);
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
  return -1;
}

std::string ServerProcess::Log() const {
  std::ifstream in(log_path_);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::shared_ptr<grpc::Channel> InsecureChannel(const std::string& address) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(-1);
  return grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments);
}

bool WaitUntilServing(const std::shared_ptr<grpc::Channel>& channel, const std::string& token,
                      std::chrono::seconds timeout) {
  auto health = grpc::health::v1::Health::NewStub(channel);
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < give_up) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(2));
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
    grpc::health::v1::HealthCheckRequest request;
    grpc::health::v1::HealthCheckResponse response;
    if (health->Check(&context, request, &response).ok() &&
        response.status() == grpc::health::v1::HealthCheckResponse::SERVING) {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace motiondb::testing
