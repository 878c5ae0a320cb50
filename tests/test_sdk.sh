#!/bin/sh
# test_sdk.sh — the plugin author's path of docs/plugins.md, end to end, against an INSTALLED murk:
#   1. `meson install --destdir` this build into a fresh temporary folder;
#   2. the installed murk runs with no LD_LIBRARY_PATH (its install RPATH finds libmurk.so.0 and
#      libmurklab.so.0, the lab, whose code libmurk does not hold) and, with no
#      MURK_PLUGIN_PATH, finds and renders with its built-in plugins (the murk/plugins folder beside
#      the installed libmurk, though the install is staged away from its prefix);
#   3. copy the installed share/murk/examples, build them out of tree with their own meson.build and
#      the installed murk-plugin.pc (PKG_CONFIG_PATH into the temporary prefix);
#   4. the installed murk lists them (MURK_PLUGIN_PATH), `murk check`s each one, and renders a scene
#      that names all three (material, tracker, integrator);
#   5. the installed murk benches that scene (charts from the installed chart script), and a program
#      built against the installed murk-lab.pc reads a plugin's schema through murk/lab.h.
# Usage: test_sdk.sh MESON   (the meson executable); MURK_BUILD_ROOT is the build folder (meson test
# sets it). Writes nothing outside one temporary folder, which it removes.
set -eu
MESON=${1:-meson}
. "$(dirname "$0")/sdk_lib.sh"
sdk_install

step "the docs, the starter scenes and the examples' scene are installed"
for f in doc/murk/README.md doc/murk/docs/plugins.md doc/murk/docs/trackers.md murk/scenes/cornell.yaml \
         murk/scenes/cornell_smoke.yaml murk/examples/examples.yaml murk/examples/README.md; do
  [ -s "$SHARE/$f" ] || fail "share/$f is not installed"
done
grep -q "murk's sources" "$EXAMPLES/README.md" && fail "the installed examples' README points into murk's sources"

step "murk help names the installed docs, examples and scenes"
env -u LD_LIBRARY_PATH "$MURK" help >"$TMP/help.txt" || fail "murk help"
REALSHARE=$(realpath "$SHARE")
for f in "$REALSHARE/doc/murk/docs/plugins.md" "$REALSHARE/murk/examples" "$REALSHARE/murk/scenes"; do
  grep -qF "$f" "$TMP/help.txt" || { cat "$TMP/help.txt"; fail "murk help does not name $f"; }
done

step "the installed murk finds libmurk through its RPATH"
readelf -d "$MURK" | grep -E 'R(UN)?PATH' | grep -q 'ORIGIN' || fail "installed murk has no \$ORIGIN RPATH"
env -u LD_LIBRARY_PATH "$MURK" --version || fail "installed murk does not start (RPATH?)"

step "the lab is libmurklab, apart from libmurk"
LIBMURK=$(find "$TMP/root" -name libmurk.so.0 | head -n 1)
LIBLAB=$(find "$TMP/root" -name libmurklab.so.0 | head -n 1)
[ -n "$LIBMURK" ] && [ -n "$LIBLAB" ] || fail "libmurk.so.0 or libmurklab.so.0 not installed"
[ -n "$(find "$TMP/root" -path '*/include/murk/lab.h')" ] || fail "murk/lab.h not installed"
nm -D --defined-only "$LIBLAB" | grep -q ' murk_lab_check$' || fail "libmurklab does not export murk_lab_check"
nm -D --defined-only "$LIBMURK" | grep -E ' murk_(lab|check|chi2|sph)_' && fail "libmurk holds the lab's code"
readelf -d "$MURK" | grep -q 'libmurklab' || fail "the installed murk does not link libmurklab"

step "the installed murk finds its built-in plugins beside its libmurk (no MURK_PLUGIN_PATH)"
# the install is staged under a destdir, not at its configured prefix: only a search relative to the
# installed libmurk can find them
env -u LD_LIBRARY_PATH -u MURK_PLUGIN_PATH "$MURK" plugins diffuse >"$TMP/builtin.txt" 2>&1 ||
  { cat "$TMP/builtin.txt"; fail "the installed murk does not find the built-in diffuse"; }
grep -qF "file: $(realpath "$BUILTINS")/diffuse.so" "$TMP/builtin.txt" ||
  { cat "$TMP/builtin.txt"; fail "diffuse.so was not taken from the installed plugin folder $BUILTINS"; }
env -u LD_LIBRARY_PATH -u MURK_PLUGIN_PATH "$MURK" render "$SHARE/murk/scenes/cornell_smoke.yaml" \
  -o "$TMP/builtin.exr" --spp 1 --set 'render.resolution=[16,16]' --quiet || fail "the installed murk does not render"
[ -s "$TMP/builtin.exr" ] || fail "the installed murk wrote no image"

step "libmurk does not link libopenvdb; the installed murk reads a .vdb through murk_vdb.so beside it"
# libopenvdb's relocations cost a process ~70 ms at start-up: only a scene that names a .vdb loads it
readelf -d "$LIBMURK" | grep -q 'libopenvdb' && fail "libmurk links libopenvdb (it should load murk_vdb.so)"
if [ -n "${MURK_VDB_WRITE:-}" ]; then
  [ -n "$(find "$TMP/root" -name murk_vdb.so -path '*/murk/murk_vdb.so')" ] || fail "murk_vdb.so not installed"
  printf 'grid density float\nmap 0.3 0.3 0.3 -0.6 0.1 -0.6\nfill 0 0 0 3 3 3 1\n' | "$MURK_VDB_WRITE" "$TMP/cube.vdb" ||
    fail "vdb_write"
  sed 's#^    density: { cloud:.*#    density: { vdb: '"$TMP"'/cube.vdb }#' "$SHARE/murk/scenes/cornell_smoke.yaml" \
    > "$TMP/vdb.yaml"
  grep -q 'cube.vdb' "$TMP/vdb.yaml" || fail "cornell_smoke.yaml's density line moved: update this test"
  env -u LD_LIBRARY_PATH -u MURK_PLUGIN_PATH "$MURK" render "$TMP/vdb.yaml" -o "$TMP/vdb.exr" --spp 1 \
    --set 'render.resolution=[16,16]' >"$TMP/vdb.log" 2>&1 || { cat "$TMP/vdb.log"; fail "the installed murk does not read a .vdb"; }
fi

step "murk-plugin.pc: headers, -lm, hidden visibility, no -lmurk"
LIBS=$(pkg-config --libs murk-plugin)
CFLAGS=$(pkg-config --cflags murk-plugin)
echo "cflags: $CFLAGS"
echo "libs: $LIBS"
echo "plugindir: $(pkg-config --variable=plugindir murk-plugin), ABI $(pkg-config --variable=abi_major murk-plugin).$(pkg-config --variable=abi_minor murk-plugin)"
for v in docdir scenesdir examplesdir; do
  [ -d "$(pkg-config --variable=$v murk-plugin)" ] || fail "murk-plugin.pc's $v is not an installed folder"
done
case " $LIBS " in *" -lmurk "*) fail "murk-plugin links libmurk" ;; esac
case " $LIBS " in *" -lm "*) ;; *) fail "murk-plugin lacks -lm" ;; esac
case " $CFLAGS " in *"-fvisibility=hidden"*) ;; *) fail "murk-plugin lacks -fvisibility=hidden" ;; esac

sdk_build_examples
for p in example_matte example_delta example_bsdfpath; do
  nm -D --defined-only "$EXB/$p.so" | grep -q murk_plugin_entry || fail "$p.so does not export murk_plugin_entry"
  nm -D --undefined-only "$EXB/$p.so" | grep -q 'murk' && fail "$p.so needs a symbol from libmurk"
  readelf -d "$EXB/$p.so" | grep -q 'libmurk' && fail "$p.so links libmurk"
done

export MURK_PLUGIN_PATH="$EXB:$BUILTINS"
unset LD_LIBRARY_PATH || true

step "murk plugins lists the examples"
"$MURK" plugins >"$TMP/plugins.txt" || { cat "$TMP/plugins.txt"; fail "murk plugins"; }
cat "$TMP/plugins.txt"
for p in example_matte example_delta example_bsdfpath; do
  grep -q "$p" "$TMP/plugins.txt" || fail "murk plugins does not list $p"
done
"$MURK" plugins example_bsdfpath || fail "murk plugins example_bsdfpath"

step "murk check on each example"
"$MURK" check --quick "$EXB/example_matte.so" || fail "murk check example_matte"
"$MURK" check --quick example_delta || fail "murk check example_delta"
"$MURK" check --quick example_bsdfpath || fail "murk check example_bsdfpath"

step "render the examples' scene, which names all three"
cp "$TMP/examples/examples.yaml" "$TMP/examples.yaml"
"$MURK" render "$TMP/examples.yaml" -o "$TMP/examples.exr" --threads 2 || fail "murk render"
[ -s "$TMP/examples.exr" ] && [ -s "$TMP/examples.png" ] || fail "murk render wrote no image"
# example_bsdfpath passes media by; volpath_nee traces example_delta's free flights through the haze
"$MURK" render "$TMP/examples.yaml" -o "$TMP/examples_vol.exr" --threads 2 --set integrator.type=volpath_nee ||
  fail "murk render with volpath_nee and example_delta"
"$MURK" compare "$TMP/examples_vol.exr" "$TMP/examples.exr" || fail "the rendered EXRs do not read back"
step "murk bench with the installed murk (its chart script found beside the installed libmurklab)"
MURK_CACHE_DIR="$TMP/cache" "$MURK" bench "$TMP/examples.yaml" --spp 1,2 --repeat 2 --ref-spp 4 \
  --set 'render.resolution=[8,6]' -o "$TMP/bench" >"$TMP/bench.log" 2>&1 || { cat "$TMP/bench.log"; fail "murk bench"; }
for f in bench.csv bench.json report.md report.html maps/variant0.npy; do
  [ -s "$TMP/bench/$f" ] || { cat "$TMP/bench.log"; fail "murk bench wrote no $f"; }
done

step "a program on the installed murk-lab.pc: a plugin's schema through murk/lab.h"
cat >"$TMP/schema.c" <<'EOF'
#include <stdio.h>
#include "murk/lab.h"
int main(void)
{
    char err[1024];
    murk_lab_plugin_info info;
    murk_lab_plugin *p = murk_lab_plugin_open("example_matte", &info, err, sizeof err);
    if (!p) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    printf("%s: %u parameters, the first %s\n", info.name, info.nparams, info.nparams ? info.params[0].name : "-");
    murk_lab_plugin_close(p);
    return 0;
}
EOF
# shellcheck disable=SC2046 # pkg-config's flags are words
# under a sanitized build (CI's stage 2) libmurklab needs its runtime in the program too
SAN=
[ "${MURK_B_SANITIZE:-none}" = none ] || SAN="-fsanitize=$MURK_B_SANITIZE"
cc -std=c11 -Wall -Wextra -Werror $SAN $(pkg-config --cflags murk-lab) -o "$TMP/schema" "$TMP/schema.c" \
  $(pkg-config --libs murk-lab) || fail "building against murk-lab.pc"
LD_LIBRARY_PATH=$(dirname "$LIBLAB") "$TMP/schema" || fail "the program on libmurklab"

echo "sdk: all steps passed"
