// Real etcd members (Debian's etcd-server) for the cluster tests: one or three, on free
// loopback ports, their data in a temporary directory on tmpfs (/dev/shm when there is one), each
// member killable, stoppable and restartable on its own ports and data.
#ifndef MOTIONDB_TESTING_ETCD_PROCESSES_H_
#define MOTIONDB_TESTING_ETCD_PROCESSES_H_

#include <sys/types.h>

#include <string>
#include <vector>

namespace motiondb::testing {

class EtcdProcesses {
 public:
  EtcdProcesses() = default;
  EtcdProcesses(const EtcdProcesses&) = delete;
  EtcdProcesses& operator=(const EtcdProcesses&) = delete;
  // Kills the members still running and removes their data.
  ~EtcdProcesses();

  // The etcd program on PATH, or "" when etcd-server is not installed.
  static std::string Binary();

  // Starts `members` members (1 or 3) as one new etcd cluster and waits until it answers
  // (false, with the members' logs in `error`, when it does not within a minute).
  bool Start(int members, std::string* error);
  // SIGKILL (`graceful`: SIGTERM) to `member`, waiting for its exit.
  void Stop(int member, bool graceful);
  // Starts `member` again on its ports and data; waits until the cluster answers through it.
  bool Restart(int member, std::string* error);

  // The running member that is raft leader now, or -1 while none is (an election under way).
  int Leader() const;

  // Every member's client address (host:port), and them comma-separated (--cluster's value).
  const std::vector<std::string>& endpoints() const { return endpoints_; }
  std::string endpoints_flag() const;

 private:
  bool Launch(int member, std::string* error);
  bool WaitUntilAnswering(const std::vector<std::string>& endpoints, std::string* error) const;
  std::string Logs() const;

  std::string dir_;
  std::vector<std::string> endpoints_;
  std::vector<std::string> peers_;
  std::vector<pid_t> pids_;
  std::string initial_cluster_;
};

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_ETCD_PROCESSES_H_
