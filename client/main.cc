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
  if (command == "help" || command == "--help" || command == "-h") {
    std::cout << kUsage;
    return 0;
  }
  std::cerr << "motiondb: unknown command '" << command << "'\n" << kUsage;
  return 2;
}
