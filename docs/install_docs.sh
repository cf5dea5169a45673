#!/bin/sh
# meson install script: copy the API reference (SRC, built by `meson compile -C build docs`) to
# DESTDIR/prefix/DOCDIR/html; nothing when it was not built.
set -eu
src=$1
dest=${MESON_INSTALL_DESTDIR_PREFIX}/$2
if [ -d "$src" ]; then
    mkdir -p "$dest"
    rm -rf "$dest/html"
    cp -R "$src" "$dest/html"
    echo "Installing API reference to $dest/html"
fi
