#!/usr/bin/env bash
# Installs the build into a scratch prefix, configures and builds tests/find_package against it
# with find_package(kirchhoff), and runs the consumer on a case file.
set -euo pipefail
build="$1" source="$2" scratch="$3"
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" > /dev/null
cmake -S "$source/tests/find_package" -B "$scratch/consumer" -DCMAKE_PREFIX_PATH="$scratch/prefix" > /dev/null
cmake --build "$scratch/consumer" > /dev/null
"$scratch/consumer/consumer" "$source/cases/simply_supported.toml"
