#!/usr/bin/env bash
# The Debian package of robodamp (docs/deployment.md, "Install the package"):
#   bash scripts/package.sh              builds build-package/robodamp_<version>_<arch>.deb and runs lintian on it
#   bash scripts/package.sh --try-install   then installs it on this machine (apt), runs robodamp --version and
#                                        bench from the installed preset, checks the units with systemd-analyze
#                                        (offline, no running systemd needed), edits the cell's conffile, removes the package
#                                        (the edited conffile stays) and purges it. Needs root; changes the machine.
# Installs what is missing first (scripts/setup.sh's packages, dpkg-dev and lintian); idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
try_install=false
for a in "$@"; do
  case "$a" in
    --try-install) try_install=true ;;
    *) echo "package.sh: unknown option '$a' (allowed: --try-install)" >&2; exit 2 ;;
  esac
done

sudo=""
[[ $(id -u) -eq 0 ]] || sudo="sudo"
missing=()
for p in dpkg-dev lintian; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "robodamp: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# The libraries: setup.sh's package list (it also builds ./build; the package's build is its own).
bash scripts/setup.sh

# Installed under /usr, looking for shipped files only there (not in this tree), without tests or benchmarks.
cmake -S . -B build-package -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
      -DROBODAMP_BUILD_TESTS=OFF -DROBODAMP_BUILD_BENCH=OFF -DROBODAMP_SEARCH_SOURCE_TREE=OFF >/dev/null
cmake --build build-package --parallel "$(nproc)" | { grep -vE '^(\[[0-9]+/[0-9]+\] |ninja: no work to do)' || true; }
rm -f build-package/robodamp_*.deb
(cd build-package && cpack -G DEB >/dev/null)
deb=$(ls build-package/robodamp_*.deb)
echo "package: $deb"
dpkg-deb --info "$deb" | grep -E '^ (Package|Version|Architecture|Depends|Recommends):'
# lintian: errors fail the build; warnings and notes are printed.
lintian --fail-on error --info "$deb" || { echo "package.sh: lintian reports errors" >&2; exit 1; }
echo "lintian: no errors"

$try_install || exit 0
if dpkg-query -W -f='${Status}' robodamp 2>/dev/null | grep -q "install ok installed"; then
  echo "package.sh: robodamp is installed already; --try-install removes what it installs: remove it first" >&2
  exit 2
fi
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "./$deb" >/dev/null
/usr/bin/robodamp --version | head -1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && /usr/bin/robodamp bench --config /usr/share/robodamp/presets/horizontal_c2.yaml --plot-dir "$work" | tail -3)
/usr/bin/robodamp check-config /etc/robodamp/robodamp.yaml | tail -1
if command -v systemd-analyze >/dev/null; then
  # Offline (no running systemd needed): the units' syntax, their commands and the manual page they name.
  out=$(SYSTEMD_LOG_LEVEL=notice systemd-analyze verify /lib/systemd/system/robodamp.service \
        /lib/systemd/system/robodamp-can.service /lib/systemd/system/robodamp-dashboard.service 2>&1)
  if [[ -n "$out" ]]; then
    echo "$out" >&2
    echo "package.sh: systemd-analyze verify has something to say about the units" >&2
    exit 1
  fi
  echo "systemd-analyze verify: the three units accepted"
else
  echo "systemd-analyze is not installed: the units are not verified"
fi
getent passwd robodamp >/dev/null && echo "user robodamp: present"
echo "# edited by package.sh" | $sudo tee -a /etc/robodamp/robodamp.yaml >/dev/null
DEBIAN_FRONTEND=noninteractive $sudo apt-get remove -y -qq robodamp >/dev/null
if grep -q "# edited by package.sh" /etc/robodamp/robodamp.yaml; then
  echo "removed: the edited /etc/robodamp/robodamp.yaml stays"
else
  echo "package.sh: removing the package lost the edited conffile" >&2
  exit 1
fi
DEBIAN_FRONTEND=noninteractive $sudo apt-get purge -y -qq robodamp >/dev/null
[[ ! -e /etc/robodamp/robodamp.yaml ]] && echo "purged: /etc/robodamp/robodamp.yaml gone"
