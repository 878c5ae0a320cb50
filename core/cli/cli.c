/* cli.c — the murk command line:
 *   murk render SCENE.yaml [-o out.exr] [--spp N] [--threads N] [--set KEY.PATH=VALUE ...] [--time S]
 *   murk info SCENE.yaml [--set KEY.PATH=VALUE ...]   (info.c)
 *   murk plugins [--markdown] [--all | NAME]   (plugins.c)
 *   murk compare A.exr B.exr [--diff d.png]
 *   murk grid OUT.vol [cloud options]     bakes the procedural cloud into a Mitsuba .vol grid
 *   murk help [COMMAND], murk COMMAND --help: usage on stdout, exit 0
 * This file is part of the murk executable, not of libmurk: it calls libmurk's MURK_API functions.
 * Exit status: 0 success, 1 bad input or failure (one line on stderr), 2 usage error. */
#include "cli/cli.h"
#include "image/image.h"
#include "load/load.h"
#include "media/density.h"
#include "media/media.h"
#include "plugin/plugin_loader.h"
#include "render/counters.h"
#include "render/mpi_job.h"
#include "scene/scene.h"
#include "util/atomic.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"
#include "murk/lab.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* `murk help COMMAND` and `murk COMMAND --help`: what each subcommand does and takes. */
static const struct command_help {
    const char *name, *text;
} command_help[] = {
    {"render",
     "usage: murk render SCENE.yaml [options]\n"
     "Renders SCENE.yaml to a linear float EXR and an sRGB PNG preview beside it.\n"
     "  -o, --output OUT.exr   the image (default: the scene's name in the current folder)\n"
     "  --spp N                samples per pixel (default: the scene's render.spp; with --time, a cap)\n"
     "  --threads N            worker threads (default: every core); the image does not depend on it\n"
     "  --set KEY.PATH=VALUE   overrides a scene key (VALUE is YAML; list items by index: shapes.0.radius=0.3);\n"
     "                         repeatable. A --set of a plugin's type (media.X.type, materials.X.type,\n"
     "                         integrator.type, media.X.transmittance.type) drops the file's keys of the\n"
     "                         previous plugin that the new one does not take. A medium or material that\n"
     "                         nothing uses is an error, so a misspelt name cannot add one silently.\n"
     "  --time S               renders whole passes until the next would not fit in S seconds\n"
     "  --checkpoint FILE      saves the render state every --every S seconds (default 60) and at the end\n"
     "  --resume FILE          continues a checkpoint (of the same scene, seed, size and --set)\n"
     "  --part I/N             renders part I of N (the 16x16 tiles t with t % N == I) for murk merge\n"
     "  -q, --quiet            no progress bar, no summary line, no notes\n"
     "Errors are one line, FILE:LINE:COL: what is wrong (or --set KEY.PATH=VALUE: what is wrong), exit 1.\n"},
    {"info",
     "usage: murk info SCENE.yaml [--set KEY.PATH=VALUE ...]\n"
     "       murk info IMAGE.png | IMAGE.exr\n"
     "Loads SCENE.yaml (with the overrides, checked as murk render checks them) and lists the render settings,\n"
     "the camera, the integrator, each medium (tracker, transmittance estimator, density grid, majorant grid),\n"
     "the materials, the shapes (with their material, interior and exterior) and the plugins each uses with the\n"
     "file each was loaded from. Renders nothing. Given an image (a name ending in .png or .exr), prints its size\n"
     "and its text keys, one 'KEY: VALUE' a line: murk:commit and murk:version say which build wrote it.\n"},
    {"plugins",
     "usage: murk plugins [--markdown] [--all | NAME]\n"
     "Without NAME: lists every plugin on the search path ($MURK_PLUGIN_PATH, then the build's or the installed\n"
     "plugin folder) with its kind, description and file. With NAME: that plugin's parameters, their types,\n"
     "defaults, ranges and descriptions (for a tracker also the keys every medium has).\n"
     "  --all        every plugin's parameters (a name found twice: the first, as a scene loads it)\n"
     "  --markdown   markdown tables instead of text, without files or versions: the list, or with NAME or\n"
     "               --all the parameters (what tools/plugin_docs.py writes into README.md and docs/plugins.md)\n"},
    {"compare",
     "usage: murk compare TEST.exr REFERENCE.exr [--crop X,Y,W,H] [--json] [--diff DIFF.png [--scale S]]\n"
     "                    [--html PAGE.html]\n"
     "Prints MSE, relMSE (mean (a-b)^2/(b^2+0.01)) with its standard error, the mean absolute relative error,\n"
     "a bias test (mean of a-b with its standard error and z-score) and, from the EXRs' render times and cost\n"
     "counters, the efficiency 1/(relMSE x seconds) and 1/(relMSE x density lookups).\n"
     "  --crop X,Y,W,H   only the pixels of that rectangle\n"
     "  --json           one JSON object instead of text\n"
     "  --diff D.png     a heat map of |a-b| (white = the 99th percentile) and D_signed.png, the signed relative\n"
     "                   difference (a-b)/(|b|+0.01) on a fixed scale: blue -S, white 0, red +S\n"
     "  --scale S        that scale (default 1)\n"
     "  --html P.html    the interactive comparison page: both images (flip, split, zoom, exposure), the error\n"
     "                   and efficiency maps and these figures, in one self-contained file\n"},
    {"bench", NULL}, /* bench.c prints its own (murk bench --help) */
    {"merge",
     "usage: murk merge OUT.exr PART.exr...\n"
     "Merges the parts of a `murk render --part I/N` render (any order) into OUT.exr and its PNG preview,\n"
     "bitwise identical to a single-process render. Every part 0..N-1 must be given once, whole, and of the\n"
     "same render (scene, --set, seed, spp, size, split, murk version, plugins); otherwise the error names it.\n"},
    {"check",
     "usage: murk check [--seed S] [--quick] [--set KEY=VALUE]... PLUGIN...\n"
     "Runs murk's statistical tests on plugins (by name or .so path): chi-square, reciprocity and furnace for\n"
     "materials; closed-form transmittance, cross-tracker agreement and heavy tails for trackers; closed-form\n"
     "means, signs and heavy tails for transmittance estimators; chi-square, normalisation, reciprocity and\n"
     "mean cosine for phase functions; a furnace for integrators. Each plugin runs with its defaults, every\n"
     "range at 25 % and 75 %, and each parameter alone at both ends of its range and at every enum and bool\n"
     "value (at most 48 sets: a WARN says what was left out); each in a process of its own (a crash is a FAIL).\n"
     "  --seed S          the random seed (default fixed)\n"
     "  --quick           fewer samples\n"
     "  --set KEY=VALUE   check one plugin at these parameter values (repeatable) instead of the sweep\n"},
    {"grid",
     "usage: murk grid OUT.vol [--min X,Y,Z] [--max X,Y,Z] [--res N] [--seed S] [--frequency F] [--octaves O]\n"
     "                 [--coverage C]\n"
     "Bakes the procedural cloud into a Mitsuba .vol density grid of N^3 voxels over the box [min, max]\n"
     "(default [-0.5,-0.5,-0.5]-[0.5,0.5,0.5], N 64, seed 1, frequency 3, octaves 5, coverage 0.5).\n"},
    {"help",
     "usage: murk help [COMMAND]\n"
     "Prints the usage of murk, or of one command (the same as murk COMMAND --help).\n"},
};

/* Prints a command's help on stdout; 0, or 2 (with the usage on stderr) for an unknown command. */
static int command_usage(const char *cmd)
{
    for (size_t i = 0; i < sizeof command_help / sizeof command_help[0]; i++)
        if (!strcmp(command_help[i].name, cmd)) {
            if (!command_help[i].text)
                return murk_lab_bench(1, (char *[]){"--help", NULL});
            fputs(command_help[i].text, stdout);
            return 0;
        }
    fprintf(stderr, "murk: no command '%s'\n", cmd);
    return murk_cli_usage(NULL);
}

/* 1 if an argument asks for help: -h or --help (not one that follows an option taking a value, such as
 * `-o -h`, which that option reads). */
static int wants_help(int argc, char **argv)
{
    static const char *const takes_value[] = {"-o", "--output", "--spp", "--threads", "--time", "--checkpoint",
                                              "--resume", "--every", "--set", "--diff", "--part",
                                              "--crop", "--scale", "--min", "--max", "--res",
                                              "--seed", "--frequency", "--octaves", "--coverage"};
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h"))
            return 1;
        for (size_t k = 0; k < sizeof takes_value / sizeof takes_value[0]; k++)
            if (!strcmp(argv[i], takes_value[k])) {
                i++;
                break;
            }
    }
    return 0;
}

#define q(s) murk_cli_q(s)
#define cli_error(m) murk_cli_error(m)
#define usage(m) murk_cli_usage(m)

static int parse_int_arg(const char *opt, const char *v, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long x = v && ((*v >= '0' && *v <= '9') || *v == '-') ? strtol(v, &end, 10) : 0;
    if (!v || !*v || !((*v >= '0' && *v <= '9') || *v == '-') || *end || errno || x < lo || x > hi) {
        fprintf(stderr, "murk: %s needs a whole number in [%ld, %ld], got '%s'\n", opt, lo, hi, q(v ? v : ""));
        return -1;
    }
    *out = x;
    return 0;
}

static char *default_output(const char *scene)
{
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    size_t n = strlen(base);
    if (n > 5 && strcmp(base + n - 5, ".yaml") == 0)
        n -= 5;
    else if (n > 4 && strcmp(base + n - 4, ".yml") == 0)
        n -= 4;
    char *out = murk_xmalloc(n + 5);
    memcpy(out, base, n);
    memcpy(out + n, ".exr", 5);
    return out;
}

static char *png_path_for(const char *exr)
{
    size_t n = strlen(exr) - 4;
    char *p = murk_xmalloc(n + 5);
    memcpy(p, exr, n);
    memcpy(p + n, ".png", 5);
    return p;
}

static void human(double v, char *buf, size_t n)
{
    if (v >= 1e9)
        snprintf(buf, n, "%.2f G", v / 1e9);
    else if (v >= 1e6)
        snprintf(buf, n, "%.2f M", v / 1e6);
    else if (v >= 1e3)
        snprintf(buf, n, "%.2f k", v / 1e3);
    else
        snprintf(buf, n, "%.0f ", v);
}

/* ---- render under MPI -------------------------------------------------------------------------
 * Every rank runs cmd_render. Until the scene is loaded, the ranks other than 0 write their messages
 * into a temporary file instead of stderr (the same warnings as rank 0's, once per rank, are noise).
 * Then all agree (murk_mpi_agree) that each loaded the same scene, --set and options (rank 0's
 * fingerprint) — or, if any failed, rank 0 prints the first failure's message naming its rank and
 * host, and every rank exits 1 before rendering. A rank that fails before that point agrees in
 * mpi_render's epilogue instead. Only rank 0 writes files and prints the summary; every rank exits
 * with rank 0's status. */
static struct {
    int size, rank, agreed, saved_fd;
    FILE *capture;
} mpi_run = {1, 0, 0, -1, NULL};

/* Stops capturing a rank's messages; the text captured (at most n - 1 bytes) into buf, if buf. */
static void mpi_uncapture(char *buf, size_t n)
{
    if (buf && n)
        buf[0] = 0;
    if (!mpi_run.capture)
        return;
    fflush(stderr);
    if (buf && n) {
        rewind(mpi_run.capture);
        size_t k = fread(buf, 1, n - 1, mpi_run.capture);
        buf[k] = 0;
    }
    dup2(mpi_run.saved_fd, STDERR_FILENO);
    close(mpi_run.saved_fd);
    fclose(mpi_run.capture);
    mpi_run.capture = NULL;
}

/* Collective, once per rank: 0 when every rank is fine and was given what rank 0 was (fingerprint),
 * else 1 after rank 0 printed the first failure. */
static int mpi_agree(int ok, const char *fingerprint, const char *why)
{
    char msg[4096], fp0[4096];
    int who;
    mpi_run.agreed = 1;
    mpi_uncapture(ok ? NULL : msg, sizeof msg);
    if (ok) {
        snprintf(fp0, sizeof fp0, "%s", fingerprint);
        murk_mpi_bcast(fp0, sizeof fp0);
        if (strcmp(fp0, fingerprint) != 0) {
            ok = 0;
            snprintf(msg, sizeof msg, "murk: rank %d (%s) was given another scene file or other options than rank "
                     "0 (%.1900s, not %.1900s)\n", mpi_run.rank, murk_mpi_host(), fingerprint, fp0);
        }
    } else {
        murk_mpi_bcast(fp0, sizeof fp0); /* matches the fine ranks' broadcast */
        if (why)
            snprintf(msg, sizeof msg, "%s", why);
    }
    if (!ok) { /* rank 0 prints it, naming where it happened */
        size_t l = strlen(msg);
        snprintf(msg + l, sizeof msg - l, "%smurk: (the error of rank %d of %d, on host %s)\n",
                 l && msg[l - 1] != '\n' ? "\n" : "", mpi_run.rank, mpi_run.size, murk_mpi_host());
    }
    int bad = murk_mpi_agree(ok, msg, sizeof msg, &who);
    if (bad && mpi_run.rank == 0 && who > 0)
        fprintf(stderr, "%s%s", msg, bad > 1 ? "murk: (other ranks failed too)\n" : "");
    return bad != 0;
}

static int render_main(int argc, char **argv);

/* cmd_render under mpirun; a process started without a launcher (or a build without MPI) renders alone. */
static int cmd_render(int argc, char **argv)
{
    char err[256] = "";
    if (murk_mpi_launched() && !murk_mpi_built()) {
        const char *r = getenv("OMPI_COMM_WORLD_RANK");
        if (!r || !strcmp(r, "0"))
            fprintf(stderr, "murk: warning: started by an MPI launcher, but this murk was built without MPI "
                    "(meson -Dmpi=enabled): every process renders the whole image alone\n");
    }
    mpi_run.size = murk_mpi_init(err, sizeof err);
    if (err[0])
        fprintf(stderr, "murk: warning: %s\n", err);
    if (mpi_run.size < 2) { /* alone (mpirun -n 1 too) */
        int rc = render_main(argc, argv);
        murk_mpi_finalize();
        return rc;
    }
    mpi_run.rank = murk_mpi_rank();
    if (mpi_run.rank > 0) {
        mpi_run.capture = tmpfile();
        mpi_run.saved_fd = mpi_run.capture ? dup(STDERR_FILENO) : -1;
        if (mpi_run.saved_fd < 0 || dup2(fileno(mpi_run.capture), STDERR_FILENO) < 0) {
            if (mpi_run.capture)
                fclose(mpi_run.capture);
            mpi_run.capture = NULL;
        }
    }
    int rc = render_main(argc, argv);
    if (!mpi_run.agreed) { /* failed before the ranks agreed: say so, and why */
        mpi_agree(0, "", NULL);
        rc = rc ? rc : 1;
    }
    int32_t rc0 = rc;
    murk_mpi_bcast(&rc0, sizeof rc0);
    murk_mpi_finalize();
    return rc0;
}

/* "--part I/N": 0 <= I < N. */
static int parse_part(const char *v, int *part, int *parts)
{
    char a[32], *slash = v ? strchr(v, '/') : NULL;
    long i, n;
    if (!slash || (size_t)(slash - v) >= sizeof a) {
        fprintf(stderr, "murk: --part needs I/N (this process renders part I of N, counted from 0), got '%s'\n",
                q(v ? v : ""));
        return -1;
    }
    memcpy(a, v, (size_t)(slash - v));
    a[slash - v] = 0;
    if (parse_int_arg("--part N", slash + 1, 1, 1 << 20, &n) || parse_int_arg("--part I", a, 0, n - 1, &i))
        return -1;
    *part = (int)i, *parts = (int)n;
    return 0;
}

/* What `murk render` was asked: the command line, the output files' names, and the texts that identify
 * the render (its --set overrides; with its part, a checkpoint's identity). */
typedef struct render_args {
    const char *scene, *out;
    const char **sets;
    size_t nsets;
    murk_render_opts opts;
    int quiet, every_given;
    char *exr, *png;
    char setbuf[4096], ckid[4200], parttag[64];
} render_args;

/* A number of seconds for opt: > 0 (positive = 1) or >= 0. 0, or 2 after the message. */
static int parse_seconds(const char *opt, const char *v, int positive, double *out)
{
    char *end;
    double t = v ? strtod(v, &end) : -1;
    if (!v || *end || !(positive ? t > 0 : t >= 0) || !isfinite(t)) {
        fprintf(stderr, "murk: %s needs %s, got '%s'\n", opt,
                positive ? "a positive number of seconds" : "a number of seconds >= 0", v ? v : "");
        return 2;
    }
    *out = t;
    return 0;
}

/* The argument argv[*i] of `murk render` (and its value, argv[*i + 1], which *i then skips). 0, or the
 * exit status of a usage error after its message. */
static int render_option(render_args *ra, int argc, char **argv, int *i)
{
    const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    murk_render_opts *o = &ra->opts;
    long x;
    int takes = 1; /* the option takes v */
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
        if (!v)
            return usage("-o needs a file name");
        ra->out = v;
    } else if (!strcmp(a, "--spp") || !strcmp(a, "--threads")) {
        if (parse_int_arg(a, v, 1, a[2] == 's' ? 1 << 24 : 1024, &x))
            return 2;
        *(a[2] == 's' ? &o->spp : &o->threads) = (int)x;
    } else if (!strcmp(a, "--time")) {
        if (parse_seconds(a, v, 1, &o->time_limit))
            return 2;
    } else if (!strcmp(a, "--checkpoint") || !strcmp(a, "--resume")) {
        if (!v || !*v)
            return usage(a[2] == 'c' ? "--checkpoint needs a file name" : "--resume needs a file name");
        *(a[2] == 'c' ? &o->checkpoint : &o->resume) = v;
    } else if (!strcmp(a, "--every")) {
        if (parse_seconds(a, v, 0, &o->checkpoint_every))
            return 2;
        ra->every_given = 1;
    } else if (!strcmp(a, "--part")) {
        if (parse_part(v, &o->part, &o->parts))
            return 2;
    } else if (!strcmp(a, "--set")) {
        if (!v)
            return usage("--set needs KEY.PATH=VALUE");
        ra->sets[ra->nsets++] = v;
    } else {
        takes = 0;
        if (!strncmp(a, "--set=", 6)) {
            ra->sets[ra->nsets++] = a + 6;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            ra->quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "murk: unknown option '%s'\n", q(a));
            return usage(NULL);
        } else if (!ra->scene) {
            ra->scene = a;
        } else {
            fprintf(stderr, "murk: more than one scene given ('%s' and '%s')\n", q(ra->scene), q(a));
            return 2;
        }
    }
    *i += takes;
    return 0;
}

/* The command line of `murk render` into ra (ra->sets to be freed). 0, or the exit status. */
static int parse_render_args(render_args *ra, int argc, char **argv)
{
    memset(ra, 0, sizeof *ra);
    ra->sets = murk_xmalloc((size_t)(argc > 0 ? argc : 1) * sizeof *ra->sets);
    ra->opts.checkpoint_every = 60;
    for (int i = 0; i < argc; i++) {
        int rc = render_option(ra, argc, argv, &i);
        if (rc)
            return rc;
    }
    if (!ra->scene)
        return usage("render needs a scene file");
    if (ra->every_given && !ra->opts.checkpoint)
        return usage("--every needs --checkpoint");
    if (ra->opts.parts && ra->opts.time_limit > 0)
        return usage("--part cannot be combined with --time: the parts of an image must have the same spp");
    return 0;
}

/* Before the scene is loaded: it is a file, the output's name ends in .exr, and (on rank 0, which writes
 * them) the EXR and its PNG preview can be written; the session checks the files it writes itself. 0, or
 * the exit status after the message. */
static int check_outputs(render_args *ra)
{
    struct stat sst;
    if (stat(ra->scene, &sst) == 0 && !S_ISREG(sst.st_mode)) { /* before deriving an output name from it */
        fprintf(stderr, "%s: is %s, not a scene file\n", q(ra->scene), /* as the loader would say it */
                S_ISDIR(sst.st_mode) ? "a directory" : S_ISFIFO(sst.st_mode) ? "a FIFO" :
                S_ISCHR(sst.st_mode) || S_ISBLK(sst.st_mode) ? "a device" : "not a regular file");
        return 1;
    }
    ra->exr = ra->out ? murk_strdup(ra->out) : default_output(ra->scene);
    size_t ol = strlen(ra->exr);
    if (ol < 5 || strcmp(ra->exr + ol - 4, ".exr") != 0) {
        fprintf(stderr, "murk: the output file must end in .exr, got '%s'\n", q(ra->exr));
        return 2;
    }
    ra->png = png_path_for(ra->exr);
    char oerr[1024]; /* a directory, device, FIFO or link, or a folder where nothing can be written */
    if (mpi_run.rank == 0 && (murk_output_probe(ra->exr, "image", oerr, sizeof oerr) ||
                              murk_output_probe(ra->png, "PNG preview", oerr, sizeof oerr))) {
        cli_error(oerr);
        return 1;
    }
    return 0;
}

/* The render's identity: its --set overrides, its part and, for a checkpoint, a part or MPI, the content
 * hash of the scene and every file it loads; under MPI every rank agrees it was given what rank 0 was. 0,
 * or 1 after the message. */
static int identify(render_args *ra, const murk_scene *s)
{
    char err[2048], fingerprint[4400];
    murk_render_opts *o = &ra->opts;
    for (size_t i = 0, k = 0; i < ra->nsets && k < sizeof ra->setbuf; i++)
        k += (size_t)snprintf(ra->setbuf + k, sizeof ra->setbuf - k, "%s%s", i ? " " : "", ra->sets[i]);
    if (o->parts)
        snprintf(ra->parttag, sizeof ra->parttag, "%d/%d", o->part, o->parts);
    if (o->checkpoint || o->resume || o->parts || mpi_run.size > 1) {
        o->scene_hash = murk_scene_hash(s, err, sizeof err); /* the YAML and every file it loads */
        /* a part's checkpoint is no other part's, nor the whole image's */
        snprintf(ra->ckid, sizeof ra->ckid, "%s%s%s", ra->setbuf, o->parts ? " --part " : "", ra->parttag);
        o->overrides = ra->ckid;
        if (!o->scene_hash) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
    }
    snprintf(fingerprint, sizeof fingerprint, "scene %016llx, spp %d, seed %llu, %dx%d, part %s, time %g, --set %s",
             (unsigned long long)o->scene_hash, o->spp > 0 ? o->spp : s->spp, (unsigned long long)s->seed,
             s->width, s->height, o->parts ? ra->parttag : "all", o->time_limit, ra->setbuf);
    return mpi_run.size > 1 && mpi_agree(1, fingerprint, NULL);
}

/* The EXR, with the render's murk:* attributes, and its PNG preview: both files or neither. 0, or 1
 * after the message. */
static int write_image(const render_args *ra, const murk_scene *s, const murk_render_result *res)
{
    char err[2048], spp[32], seed[32], secs[32], nonfinite[32], plugins[4096], interrupted[96] = "no";
    char spp_asked[32], ranks[32], threads[32], tsecs[32], hash[32], exposure[32], ntiles[32], maxsample[40];
    static char counters[16384];
    const murk_render_opts *o = &ra->opts;
    snprintf(maxsample, sizeof maxsample, "%.17g", res->max_sample);
    murk_registry_describe(&s->reg, plugins, sizeof plugins);
    snprintf(spp, sizeof spp, "%d", res->spp);
    snprintf(spp_asked, sizeof spp_asked, "%d", o->spp > 0 ? o->spp : s->spp);
    if (res->interrupted)
        snprintf(interrupted, sizeof interrupted, "%s after %d of %s spp", murk_cli_stop_name(), res->spp, spp_asked);
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)s->seed);
    snprintf(secs, sizeof secs, "%.3f", res->seconds);
    snprintf(nonfinite, sizeof nonfinite, "%llu", (unsigned long long)res->nonfinite);
    murk_counters_json(s, res, counters, sizeof counters);
    snprintf(ranks, sizeof ranks, "%d", res->ranks);
    snprintf(threads, sizeof threads, "%d", res->threads);
    snprintf(tsecs, sizeof tsecs, "%.3f", res->thread_seconds);
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)o->scene_hash);
    snprintf(exposure, sizeof exposure, "%.9g", (double)s->exposure);
    snprintf(ntiles, sizeof ntiles, "%d", murk_part_tiles(res->width, res->height, o->part, o->parts));
    murk_kv meta[] = {
        {"murk:scene", ra->scene}, {"murk:spp", spp}, {"murk:seed", seed}, {"murk:render_time", secs},
        {"murk:version", MURK_VERSION}, {"murk:commit", murk_build_commit()}, {"murk:integrator", s->integrator_plugin->desc->name},
        {"murk:nonfinite_samples", nonfinite}, {"murk:set", ra->setbuf}, {"murk:plugins", plugins},
        {"murk:spp_requested", spp_asked}, {"murk:interrupted", interrupted},
        {"murk:resumed_from", o->resume ? o->resume : ""}, {"murk:counters", counters},
        {"murk:max_sample", maxsample}, /* the largest channel of a finite sample (murk bench --assemble) */
        /* the job: processes, render threads, seconds those threads spent in tiles (summed over ranks) */
        {"murk:ranks", ranks}, {"murk:threads", threads}, {"murk:thread_time", tsecs},
        /* a --part render: what murk merge checks and needs */
        {"murk:part", ra->parttag}, {"murk:part_split", "tiles"}, {"murk:part_tiles", ntiles},
        {"murk:scene_hash", hash}, {"murk:exposure", exposure},
    };
    int nmeta = (int)(sizeof meta / sizeof meta[0]) - (o->parts ? 0 : 5); /* the murk:part... keys last */
    if (res->interrupted)
        fprintf(stderr, "murk: interrupted (%s): writing the image with %d of %s spp%s%s\n", murk_cli_stop_name(),
                res->spp, spp_asked, o->checkpoint ? "; resume with --resume " : "", o->checkpoint ? o->checkpoint : "");
    murk_output_begin();
    if (murk_exr_write(ra->exr, res->rgb, res->width, res->height, meta, nmeta, err, sizeof err) != 0 ||
        murk_png_write(ra->png, res->rgb, res->width, res->height, s->exposure, err, sizeof err) != 0 ||
        murk_output_commit(err, sizeof err) != 0) {
        murk_output_abort();
        cli_error(err);
        return 1;
    }
    return 0;
}

/* Renders the loaded scene, writes its image on rank 0 and says how it went. The exit status. */
static int render_loaded(render_args *ra, const murk_scene *s, volatile sig_atomic_t *stop)
{
    char err[2048];
    if (identify(ra, s))
        return 1;
    ra->opts.progress = !ra->quiet && murk_cli_progress();
    ra->opts.stop = stop;
    murk_render_result res;
    if (murk_render_err(s, &ra->opts, &res, err, sizeof err) != 0) {
        if (err[0])
            fprintf(stderr, "murk: %s\n", err);
        if (!res.rgb)
            return 1;
    }
    int rc = err[0] != 0; /* a checkpoint that failed: the image of the passes done is written, and exit 1 */
    if (mpi_run.rank > 0) { /* rank 0 writes the image; this rank's status is rank 0's */
        murk_warn_summary();
        return 0;
    }
    rc |= write_image(ra, s, &res);
    if (res.interrupted || *stop) /* also when the signal came during the writes and cut them short */
        rc = murk_cli_stop_status();
    if (rc == 0 && !ra->quiet) {
        char sps[32], rps[32];
        human((double)res.samples / res.seconds, sps, sizeof sps);
        human((double)res.rays / res.seconds, rps, sizeof rps);
        printf("%s, %s: %dx%d, %d spp, %.2f s, %ssamples/s, %srays/s\n", ra->exr, ra->png, res.width, res.height,
               res.spp, res.seconds, sps, rps);
        murk_counters_print(stdout, s, &res);
        murk_cli_memory_print(stdout, s, 0);
    }
    murk_warn_summary();
    if (res.nonfinite)
        murk_log(MURK_LOG_WARN, "integrator '%s' [%s] returned %llu NaN or infinite samples; they were left out of "
                 "their pixels", s->integrator_plugin->desc->name, s->integrator_plugin->path,
                 (unsigned long long)res.nonfinite);
    free(res.rgb);
    return rc;
}

static int render_main(int argc, char **argv)
{
    volatile sig_atomic_t *stop = murk_cli_catch_stop_signals();
    render_args ra;
    int rc = parse_render_args(&ra, argc, argv);
    if (rc == 0)
        rc = check_outputs(&ra);
    if (rc == 0) {
        murk_set_quiet(ra.quiet);
        murk_scene *s = murk_cli_load(ra.scene, ra.sets, ra.nsets);
        rc = s ? render_loaded(&ra, s, stop) : 1;
        if (s)
            murk_scene_free(s);
    }
    free(ra.exr);
    free(ra.png);
    free(ra.sets);
    return rc;
}

/* ---- grid ---------------------------------------------------------------------------------- */

/* A number read as strictly as the scene's (yread.c): a whole decimal token, no leading space, no hex,
 * no nan or inf; whole = 1 also refuses a fraction. 0, or -1 after a message naming the problem. */
static int parse_number(const char *opt, const char *v, int whole, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    int ok = v && *v && (*v == '-' || *v == '+' || *v == '.' || (*v >= '0' && *v <= '9')) &&
             !(v[0] == '0' && (v[1] == 'x' || v[1] == 'X'));
    double x = ok ? strtod(v, &end) : 0;
    if (!ok || *end || !isfinite(x)) {
        fprintf(stderr, "murk: %s needs %s, got '%s'\n", opt, whole ? "a whole number" : "a number", q(v ? v : ""));
        return -1;
    }
    if (whole && x != floor(x)) {
        fprintf(stderr, "murk: %s must be a whole number, got '%s'\n", opt, q(v));
        return -1;
    }
    if (!(x >= lo && x <= hi)) {
        fprintf(stderr, "murk: %s must be in [%.*g, %.*g], got '%s'\n", opt, whole ? 12 : 6, lo, whole ? 12 : 6, hi, q(v));
        return -1;
    }
    *out = x;
    return 0;
}

static int parse_vec3_arg(const char *opt, const char *v, murk_vec3 *out)
{
    double c[3];
    char part[3][128];
    const char *p = v;
    for (int k = 0; k < 3; k++) {
        const char *e = p ? strchr(p, ',') : NULL;
        if (k == 2)
            e = p ? p + strlen(p) : NULL;
        if (!p || !e || (size_t)(e - p) >= sizeof part[k] || (k == 2 && strchr(p, ','))) {
            fprintf(stderr, "murk: %s needs X,Y,Z, got '%s'\n", opt, q(v ? v : ""));
            return -1;
        }
        memcpy(part[k], p, (size_t)(e - p));
        part[k][e - p] = 0;
        p = *e ? e + 1 : NULL;
    }
    for (int k = 0; k < 3; k++)
        if (parse_number(opt, part[k], 0, -MURK_MAX_COORD, MURK_MAX_COORD, &c[k]))
            return -1;
    *out = murk_v3((float)c[0], (float)c[1], (float)c[2]);
    return 0;
}

/* Bakes the procedural cloud into a Mitsuba .vol file, so grid-based scenes and tests have data. */
static int cmd_grid(int argc, char **argv)
{
    const char *out = NULL;
    murk_vec3 lo = murk_v3(-0.5f, -0.5f, -0.5f), hi = murk_v3(0.5f, 0.5f, 0.5f);
    double res = 64, seed = 1, freq = 3, oct = 5, cov = 0.5;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if (!strcmp(a, "--min"))
            bad = parse_vec3_arg(a, v, &lo), i++;
        else if (!strcmp(a, "--max"))
            bad = parse_vec3_arg(a, v, &hi), i++;
        else if (!strcmp(a, "--res"))
            bad = parse_number(a, v, 1, 2, 1024, &res), i++;
        else if (!strcmp(a, "--seed"))
            bad = parse_number(a, v, 1, 0, 4294967295.0, &seed), i++;
        else if (!strcmp(a, "--frequency"))
            bad = parse_number(a, v, 0, 0.01, 1000, &freq), i++;
        else if (!strcmp(a, "--octaves"))
            bad = parse_number(a, v, 1, 1, 16, &oct), i++;
        else if (!strcmp(a, "--coverage"))
            bad = parse_number(a, v, 0, 0, 1, &cov), i++;
        else if (a[0] == '-') {
            fprintf(stderr, "murk: unknown grid option '%s'\n", q(a));
            return usage(NULL);
        } else if (!out)
            out = a;
        else
            return usage("grid takes one output file");
        if (bad)
            return 2;
    }
    if (!out)
        return usage("grid needs an output .vol file");
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) {
        fprintf(stderr, "murk: --max must exceed --min on every axis\n");
        return 2;
    }
    char err[1024];
    if (murk_output_check(out, err, sizeof err) != 0) { /* before the work: never a device or a directory */
        cli_error(err);
        return 1;
    }
    double voxels = res * res * res;
    if (voxels > (double)murk_limit(MURK_LIMIT_GRID_VOXELS)) {
        fprintf(stderr, "murk: --res %.0f gives %.0f voxels, beyond the limit of %llu (%s)\n", res, voxels,
                (unsigned long long)murk_limit(MURK_LIMIT_GRID_VOXELS), murk_limit_name(MURK_LIMIT_GRID_VOXELS));
        return 1;
    }
    murk_field *f = murk_field_cloud(lo, hi, (int)res, (uint64_t)seed, (float)freq, (int)oct, (float)cov);
    if (!f) {
        fprintf(stderr, "murk: could not build the cloud: out of memory\n");
        return 1;
    }
    if (!(murk_field_max(f) > 0.0f))
        fprintf(stderr, "murk: warning: the cloud is empty (every voxel is 0 at --res %.0f, --coverage %g); the grid "
                "holds no density\n", res, cov);
    int rc = murk_field_vol_save(out, f, err, sizeof err);
    if (rc)
        cli_error(err);
    else
        printf("%s: %dx%dx%d cloud over [%g,%g,%g]-[%g,%g,%g], max density %g\n", q(out), (int)res, (int)res, (int)res,
               lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, murk_field_max(f));
    murk_field_free(f);
    return rc ? 1 : 0;
}

/* The data folder (holding murk/examples, murk/scenes, doc/murk) of the running murk: DATADIR relative to
 * its executable if that holds murk's examples (an install, moved or staged with --destdir), else the
 * configured prefix's. */
static void installed_datadir(char *out, size_t n)
{
    char exe[4096], dir[4096 + 64];
    ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (k > 0) {
        exe[k] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = 0;
            snprintf(dir, sizeof dir, "%s/%s/murk/examples", exe, MURK_DATADIR_FROM_BINDIR);
            char real[4096];
            if (realpath(dir, real) && strlen(real) > strlen("/murk/examples")) {
                real[strlen(real) - strlen("/murk/examples")] = 0;
                snprintf(out, n, "%s", real);
                return;
            }
        }
    }
    snprintf(out, n, "%s", MURK_DATADIR);
}

/* `murk help`'s last lines: where the guide, the example plugins and the starter scenes are, for this
 * murk (the sources' when it runs from its build tree). */
static void print_files(void)
{
    if (murk_running_uninstalled()) {
        printf("\nfiles (murk runs from its build tree: the sources at %s)\n"
               "  docs         %s/README.md, %s/docs/plugins.md (writing plugins)\n"
               "  examples     %s/plugins/examples (three plugins to copy, their meson.build, examples.yaml)\n"
               "  scenes       %s/scenes\n",
               MURK_SOURCE_ROOT, MURK_SOURCE_ROOT, MURK_SOURCE_ROOT, MURK_SOURCE_ROOT, MURK_SOURCE_ROOT);
        return;
    }
    char d[4096];
    installed_datadir(d, sizeof d);
    printf("\nfiles\n"
           "  docs         %s/doc/murk/README.md, %s/doc/murk/docs/plugins.md (writing plugins)\n"
           "  examples     %s/murk/examples (three plugins to copy, their meson.build, examples.yaml)\n"
           "  scenes       %s/murk/scenes (starter scenes)\n",
           d, d, d, d);
}

int murk_cli_main(int argc, char **argv)
{
    if (argc < 2)
        return usage(NULL);
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--version")) {
        printf("murk %s (commit %s, plugin ABI %d.%d)\n", MURK_VERSION, murk_build_commit(), MURK_ABI_MAJOR,
               MURK_ABI_MINOR);
        return 0;
    }
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || (!strcmp(cmd, "help") && argc == 2)) {
        fputs(murk_cli_usage_text, stdout);
        print_files();
        return 0;
    }
    int known = 0;
    for (size_t i = 0; i < sizeof command_help / sizeof command_help[0]; i++)
        known |= !strcmp(command_help[i].name, cmd);
    if (known && wants_help(argc - 2, argv + 2))
        return command_usage(cmd);
    if (!strcmp(cmd, "help"))
        return argc == 3 ? command_usage(argv[2]) : usage("help takes at most one command");
    if (!strcmp(cmd, "render"))
        return cmd_render(argc - 2, argv + 2);
    if (!strcmp(cmd, "info"))
        return murk_cli_info(argc - 2, argv + 2);
    if (!strcmp(cmd, "plugins"))
        return murk_cli_plugins(argc - 2, argv + 2);
    if (!strcmp(cmd, "compare"))
        return murk_lab_compare(argc - 2, argv + 2);
    if (!strcmp(cmd, "bench"))
        return murk_lab_bench(argc - 2, argv + 2);
    if (!strcmp(cmd, "check"))
        return murk_lab_check(argc - 2, argv + 2);
    if (!strcmp(cmd, "grid"))
        return cmd_grid(argc - 2, argv + 2);
    if (!strcmp(cmd, "merge"))
        return murk_cli_merge(argc - 2, argv + 2);
    fprintf(stderr, "murk: unknown command '%s'\n", q(cmd));
    return usage(NULL);
}
