#!/usr/bin/env bash
# Builds the Blender add-on's installable zip from client/blender/motiondb_blender.
#   scripts/blender-addon.sh [ZIP]    default: $BUILD_DIR/motiondb_blender.zip (BUILD_DIR: build/)
# Install it in Blender: Edit > Preferences > Add-ons > Install..., pick the zip, tick
# "Animation: motiondb". The zip holds the folder motiondb_blender/ (the add-on's module name)
# and its .py files only, not Python's caches.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
zip="${1:-${BUILD_DIR:-$root/build}/motiondb_blender.zip}"
mkdir -p "$(dirname "$zip")"
/usr/bin/python3 - "$root/client/blender/motiondb_blender" "$zip" <<'PY'
import pathlib
import sys
import zipfile

source, zip_path = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
files = sorted(source.glob("*.py"))
if not (source / "__init__.py").is_file():
    sys.exit(f"{source} has no __init__.py")
part = zip_path.with_name(zip_path.name + ".part")
with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as archive:
    for path in files:
        archive.write(path, f"{source.name}/{path.name}")
part.replace(zip_path)
print(f"{zip_path}: the Blender add-on ({len(files)} files); install it with Edit > "
      "Preferences > Add-ons > Install...")
PY
