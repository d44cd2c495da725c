#include "testing/server_process.h"

#include <signal.h>
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
#include "testing/child_process.h"

namespace motiondb::testing {

std::string ServerPath() {
  const char* given = std::getenv("MOTIONDB_SERVER_BIN");
  return given != nullptr && *given != '\0' ? given : MOTIONDB_SERVER_PATH;
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) StopChild(pid_, SIGKILL, std::chrono::seconds(30));
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
  pid_ = SpawnChild(argv_strings, ChildOptions{.log_path = log_path_,
                                               .stdout_to_log = false,
                                               .append = false,
                                               .max_open_files = max_open_files_});
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
    if (const std::optional<int> code = ExitedChild(pid_)) {
      pid_ = -1;
      *error = "the server exited with code " + std::to_string(*code) + ":\n" + Log();
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  *error = "the server did not report its port in time:\n" + Log();
  return false;
}

int ServerProcess::Stop(int signal, std::chrono::seconds timeout) {
  if (pid_ <= 0) return -1;
  const int code = StopChild(pid_, signal, timeout);
  pid_ = -1;
  return code;
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
