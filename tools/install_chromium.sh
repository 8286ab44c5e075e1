#!/usr/bin/env bash
# Make sure the system's Chromium and chromedriver exist (Debian packages `chromium`,
# `chromium-driver`); the rendered-page check (nox -s book_check) drives them with selenium.
# Installs them with apt when missing and run as root; never downloads a browser otherwise.
set -euo pipefail
if command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1; then
  exit 0
fi
if [ "$(id -u)" != "0" ] || ! command -v apt-get >/dev/null 2>&1; then
  echo "chromium/chromedriver missing: install the Debian packages 'chromium' and 'chromium-driver'" >&2
  echo "(e.g. sudo apt-get update && sudo apt-get install chromium chromium-driver)" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends chromium chromium-driver >/dev/null
command -v chromium && command -v chromedriver
