// motiondb: the command-line client.
#include <iostream>
#include <string>
#include <vector>
#include "absl/strings/string_view.h"

#include "client/commands.h"

namespace {

constexpr char kUsage[] =
    "usage: motiondb COMMAND [ARGS]\n"
    "\n"
    "Offline commands (no server needed):\n"
    "  inspect FILE... [--json]                         describe BVH files\n"
    "  convert IN.bvh OUT.bvh [--fps R] [--from F --to T]  resample and/or cut a BVH file\n"
    "  space build --train FILE[:FROM-TO]... --out SPACE.mcs [--rate 30]\n"
    "        [--weights mass|uniform|FILE.json] [--keep-heading] [--json]\n"
    "                                                   build a Motion Curve space\n"
    "  project FILE.bvh --space SPACE.mcs [--dims 3] [--csv]  print a clip's motion curve\n"
    "\n"
    "Server commands (--server ADDR, default 127.0.0.1:50051; --token T or $MOTIONDB_TOKEN;\n"
    "--tls-ca FILE; --timeout S; --json on every command for machine-readable output):\n"
    "  ingest PATH... [--tag T]... [--recursive]        upload BVH files or folders\n"
    "  clips [--tag T]                                  list clips\n"
    "  clip show ID | clip delete ID                    one clip\n"
    "  export ID [--from F --to T] -o OUT.bvh           download a clip or a range of it\n"
    "  space create NAME [--train CLIP[:FROM-TO]]... [--rate R] [--weights mass|uniform|FILE]\n"
    "        [--keep-heading] [--metric unit|eigen]    build a space on the server\n"
    "  space list | space show NAME | space delete NAME\n"
    "  search --space NAME (--clip ID [--from F --to T] | --bvh FILE) [--neighbours K]\n"
    "        [--ann-dims N] [--dtw-dims N] [--epsilon E] [--slope S] [--char-frame F]\n"
    "        [--neutral mean|boundary|origin] [--max N] [--exact]   query by example\n"
    "  info                                             server version, contents, indices\n"
    "\n"
    "Frame numbers count from 0 at the clip's own rate; ranges are inclusive.\n";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << kUsage;
    return 2;
  }
  const absl::string_view command = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  if (command == "inspect") return motiondb::cli::RunInspect(args);
  if (command == "convert") return motiondb::cli::RunConvert(args);
  if (command == "space") return motiondb::cli::RunSpace(args);
  if (command == "project") return motiondb::cli::RunProject(args);
  if (command == "ingest") return motiondb::cli::RunIngest(args);
  if (command == "clips") return motiondb::cli::RunClips(args);
  if (command == "clip") return motiondb::cli::RunClip(args);
  if (command == "export") return motiondb::cli::RunExport(args);
  if (command == "search") return motiondb::cli::RunSearch(args);
  if (command == "info") return motiondb::cli::RunInfo(args);
  if (command == "help" || command == "--help" || command == "-h") {
    std::cout << kUsage;
    return 0;
  }
  std::cerr << "motiondb: unknown command '" << command << "'\n" << kUsage;
  return 2;
}
