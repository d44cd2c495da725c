// Runs the real motiondb-server binary for integration tests and the server benchmark: on free
// loopback ports (the server picks them, --listen 127.0.0.1:0 and --http 127.0.0.1:0, and logs
// them), with its stderr captured to a file in the temporary directory, and stopped by a signal
// like an operator would.
#ifndef MOTIONDB_TESTING_SERVER_PROCESS_H_
#define MOTIONDB_TESTING_SERVER_PROCESS_H_

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

namespace motiondb::testing {

class ServerProcess {
 public:
  ServerProcess() = default;
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;
  // Kills a server still running (SIGKILL): a failed test must not leave it behind.
  ~ServerProcess();

  // Starts the server with --listen 127.0.0.1:0, --http 127.0.0.1:0 (unless `args` hold an
  // --http of their own) and `args`, and waits until it logs its ports (false, with the log in
  // `error`, when it exits or takes longer than `timeout`).
  bool Start(const std::vector<std::string>& args, std::string* error,
             std::chrono::seconds timeout = std::chrono::seconds(60));
  // Sends `signal` and waits for the exit; returns the exit code, or 128 + the signal that
  // killed it, or -1 when it did not stop within `timeout` (it is then killed).
  int Stop(int signal, std::chrono::seconds timeout = std::chrono::seconds(30));

  // The open-file limit (soft and hard) the next Start() gives the server, as `prlimit
  // --nofile=N:N` would; 0: the test's own.
  void LimitOpenFiles(int files) { max_open_files_ = files; }

  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  int port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  // The HTTP face's port; 0 with --http off.
  int http_port() const { return http_port_; }
  // Everything the server wrote to stderr so far.
  std::string Log() const;

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  int http_port_ = 0;
  int max_open_files_ = 0;
  std::string log_path_;
};

// The built motiondb-server, or the one MOTIONDB_SERVER_BIN names (a benchmark's baseline).
std::string ServerPath();

// A channel to `address` without TLS and without message size limits on what it receives.
std::shared_ptr<grpc::Channel> InsecureChannel(const std::string& address);

// Polls the standard health service until it answers SERVING (false after `timeout`).
// `token`, when not empty, is sent as a bearer token.
bool WaitUntilServing(const std::shared_ptr<grpc::Channel>& channel, const std::string& token,
                      std::chrono::seconds timeout = std::chrono::seconds(30));

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_SERVER_PROCESS_H_
