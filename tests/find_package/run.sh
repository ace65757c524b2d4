#!/usr/bin/env bash
# Installs the build into a scratch prefix, configures and builds tests/find_package against it
# with find_package(kirchhoff), and runs the consumer on a case file. Only the public headers
# (lib/CMakeLists.txt, listed in BUILD/kirchhoff_public_headers.txt as LAYER/NAME.hpp) are installed: any other
# header in the prefix fails the test, and a translation unit including every public header is
# compiled against the prefix, so a public header that includes an internal one fails the build.
# The consumer solves, continues and sweeps (main.cpp); the sweep writes into a scratch folder.
set -euo pipefail
build="$1" source="$2" scratch="$3"
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" > /dev/null
public="$build/kirchhoff_public_headers.txt"
[ -s "$public" ] || { echo "no list of public headers: $public" >&2; exit 1; }
installed="$scratch/prefix/include/kirchhoff"
all="$scratch/all_public_headers.cpp"
mkdir -p "$scratch"
: > "$all"
count=0
while read -r header; do  # LAYER/NAME.hpp
  [ -f "$installed/$header" ] || { echo "public header not installed: $header" >&2; exit 1; }
  echo "#include <kirchhoff/$header>" >> "$all"
  count=$((count + 1))
done < "$public"
while read -r file; do
  header=${file#"$installed"/}
  grep -qxF "$header" "$public" || { echo "installed but not public: $header" >&2; exit 1; }
done < <(find "$installed" -type f)
echo "compiling the $count public headers from the installed tree"
cmake -S "$source/tests/find_package" -B "$scratch/consumer" -DCMAKE_PREFIX_PATH="$scratch/prefix" \
      -DKIRCHHOFF_ALL_HEADERS="$all" > /dev/null
cmake --build "$scratch/consumer" > /dev/null
mkdir -p "$scratch/sweep"
"$scratch/consumer/consumer" "$source/cases/simply_supported.toml" "$scratch/sweep"
