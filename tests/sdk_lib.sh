# sdk_lib.sh — what test_sdk.sh and test_examples.sh share, sourced by both (POSIX sh): a temporary
# folder removed at exit, murk installed into it with `meson install --destdir`, and the installed
# examples copied and built out of tree against the installed murk-plugin.pc.
# The caller sets MESON (the meson executable) and MURK_BUILD_ROOT (the build folder; meson test sets it).
BUILD=${MURK_BUILD_ROOT:?MURK_BUILD_ROOT must name the build folder}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/murk-sdk-XXXXXX")
trap 'rm -rf "$TMP"' EXIT INT TERM
export TMPDIR="$TMP" # murk check's scratch folder too
step() { printf '== %s\n' "$*"; }
fail() { printf 'FAIL: %s\n' "$*"; exit 1; }

# Installs the build under $TMP/root; sets MURK, PCFILE, EXAMPLES, BUILTINS (the plugin folder), SHARE.
sdk_install() {
  step "meson install --destdir $TMP/root"
  "$MESON" install -C "$BUILD" --destdir "$TMP/root" --no-rebuild --quiet >"$TMP/install.log" 2>&1 ||
    { cat "$TMP/install.log"; fail "meson install"; }
  MURK=$(find "$TMP/root" -type f -name murk -path '*/bin/murk' | head -n 1)
  PCFILE=$(find "$TMP/root" -name murk-plugin.pc | head -n 1)
  EXAMPLES=$(find "$TMP/root" -type d -path '*/share/murk/examples' | head -n 1)
  BUILTINS=$(find "$TMP/root" -type f -name diffuse.so -path '*/murk/plugins/*' | head -n 1)
  [ -n "$MURK" ] || fail "no bin/murk installed"
  [ -n "$PCFILE" ] || fail "no murk-plugin.pc installed"
  [ -n "$EXAMPLES" ] || fail "no share/murk/examples installed"
  [ -n "$BUILTINS" ] || fail "no built-in plugins installed"
  BUILTINS=$(dirname "$BUILTINS")
  SHARE=$(dirname "$(dirname "$EXAMPLES")") # PREFIX/share
  export PKG_CONFIG_PATH="$(dirname "$PCFILE")"
  export PKG_CONFIG_SYSROOT_DIR="$TMP/root" # the files name the real prefix; they live under the destdir
}

# Copies the installed examples to $TMP/examples and builds them there with their own meson.build (no
# options: what an author who copies them gets); sets EXB, the build folder.
sdk_build_examples() {
  step "build the installed examples out of tree"
  cp -R "$EXAMPLES" "$TMP/examples"
  "$MESON" setup "$TMP/examples/build" "$TMP/examples" >"$TMP/setup.log" 2>&1 || { cat "$TMP/setup.log"; fail "meson setup of the examples"; }
  "$MESON" compile -C "$TMP/examples/build" >"$TMP/compile.log" 2>&1 || { cat "$TMP/compile.log"; fail "building the examples"; }
  grep -i "warning" "$TMP/compile.log" && fail "the examples compile with warnings"
  # a release build by default: -O0 (meson's default) would make an example tracker time slower than it is
  "$MESON" introspect --buildoptions "$TMP/examples/build" | tr -d ' \n' | grep -q '"name":"buildtype","value":"release"' ||
    fail "the examples' meson.build does not default to a release build"
  EXB="$TMP/examples/build"
  for p in example_matte example_delta example_bsdfpath; do
    [ -f "$EXB/$p.so" ] || fail "$p.so was not built"
  done
}
