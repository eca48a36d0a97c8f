#!/bin/sh
# pip_install.sh VENV SOURCE BUILD PYTHON — ctest's python_pip_install fixture:
# the Python suite runs against autumnc as pip installs it, not against the
# build tree's copy. A new venv each run (PYTHON -m venv --system-site-packages,
# PYTHON being the interpreter the tree is built for, /usr/bin/python3; without
# pip of its own: Debian's pip, numpy and pytest come from the system site),
# then `pip install --no-build-isolation --no-index SOURCE` with
# AUTUMNC_CMAKE_BUILD_DIR=BUILD, so setup.py only runs an incremental build of
# _core in the tree ctest is testing and copies the result: seconds, no
# network. Quiet unless it fails; then pip's output (with the CMake build's)
# is printed.
set -eu
venv=$1 source=$2 build=$3 python=$4
log=$build/pip-install.log
rm -rf "$venv"
"$python" -m venv --system-site-packages --without-pip "$venv"
# Nothing but the checkout and the system site: no pip configuration (files or
# PIP_* variables naming indexes or wheel folders), no index.
unset PIP_FIND_LINKS PIP_INDEX_URL PIP_EXTRA_INDEX_URL PIP_NO_INDEX PIP_USER PIP_TARGET PIP_PREFIX
if ! AUTUMNC_CMAKE_BUILD_DIR=$build PIP_CONFIG_FILE=/dev/null PIP_DISABLE_PIP_VERSION_CHECK=1 \
    "$venv/bin/python" -m pip install --no-build-isolation --no-index --no-cache-dir "$source" >"$log" 2>&1; then
  cat "$log"
  echo "pip_install.sh: pip install of $source into $venv failed (above; also in $log)" >&2
  exit 1
fi
