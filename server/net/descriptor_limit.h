// The process's open-file limit: every connection, on either port, holds a descriptor, and a
// process out of descriptors fails in places it cannot recover from (gRPC 1.51's own listener
// stopped for good after one EMFILE, grpc/grpc#20418; its pollers need eventfds).
#ifndef MOTIONDB_SERVER_NET_DESCRIPTOR_LIMIT_H_
#define MOTIONDB_SERVER_NET_DESCRIPTOR_LIMIT_H_

namespace motiondb::server {

// Descriptors kept for what is not a connection: the database and its journal, gRPC's pollers
// and wakeup fds, threads' eventfds, the web UI's files being served, logs.
inline constexpr int kReservedDescriptors = 128;

// Raises the soft limit on open files to the hard limit (an operator's `ulimit -Hn`, or what
// `prlimit --nofile` or the container allows) and returns the soft limit in force.
int RaiseOpenFileLimit();

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_NET_DESCRIPTOR_LIMIT_H_
