#include "testing/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <thread>

namespace motiondb::testing {

pid_t SpawnChild(const std::vector<std::string>& argv, const ChildOptions& options) {
  // Built before fork: the child of a threaded parent must not allocate.
  std::vector<char*> pointers;
  for (const std::string& arg : argv) pointers.push_back(const_cast<char*>(arg.c_str()));
  pointers.push_back(nullptr);
  const int log_flags = O_WRONLY | O_CREAT | (options.append ? O_APPEND : O_TRUNC);
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  const int log = ::open(options.log_path.c_str(), log_flags, 0644);
  const int null = ::open("/dev/null", O_RDWR);
  if (log < 0 || null < 0) ::_exit(126);
  ::dup2(null, STDIN_FILENO);
  ::dup2(options.stdout_to_log ? log : null, STDOUT_FILENO);
  ::dup2(log, STDERR_FILENO);
  if (options.max_open_files > 0) {
    const rlimit files{static_cast<rlim_t>(options.max_open_files),
                       static_cast<rlim_t>(options.max_open_files)};
    if (::setrlimit(RLIMIT_NOFILE, &files) != 0) ::_exit(125);
  }
  ::execv(pointers[0], pointers.data());
  ::_exit(127);
}

std::optional<int> ExitedChild(pid_t pid) {
  int status = 0;
  if (::waitpid(pid, &status, WNOHANG) != pid) return std::nullopt;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

int StopChild(pid_t pid, int signal, std::chrono::milliseconds timeout) {
  ::kill(pid, signal);
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < give_up) {
    if (const std::optional<int> code = ExitedChild(pid)) return *code;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return -1;
}

}  // namespace motiondb::testing
