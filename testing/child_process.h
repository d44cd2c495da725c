// Starting and stopping the programs tests run as child processes (motiondb-server, etcd): one
// fork/exec with stdin from /dev/null and output to a log file, and one stop by a signal that
// reports the exit as a shell would, so the two harnesses do not each carry their own.
#ifndef MOTIONDB_TESTING_CHILD_PROCESS_H_
#define MOTIONDB_TESTING_CHILD_PROCESS_H_

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace motiondb::testing {

struct ChildOptions {
  // Where stderr goes (and stdout with `stdout_to_log`; otherwise /dev/null).
  std::string log_path;
  bool stdout_to_log = false;
  // Appends to the log; otherwise truncates it.
  bool append = false;
  // The open-file limit (soft and hard) the child gets; 0: the parent's.
  int max_open_files = 0;
};

// Forks and execs `argv` (argv[0] a path); the pid, or -1 when fork fails. A child that cannot
// open its log exits 126, cannot set its limit 125, cannot exec 127.
pid_t SpawnChild(const std::vector<std::string>& argv, const ChildOptions& options);

// The exit code of `pid` (128 + the signal that killed it) once it has exited, reaping it; nullopt
// while it runs.
std::optional<int> ExitedChild(pid_t pid);

// Sends `signal` to `pid` and reaps it; returns its exit code as ExitedChild does, or -1 when it
// did not exit within `timeout` (it is then killed).
int StopChild(pid_t pid, int signal, std::chrono::milliseconds timeout);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_CHILD_PROCESS_H_
