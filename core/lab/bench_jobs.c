/* bench_jobs.c — `murk bench` as jobs (bench.h): --emit-jobs DIR writes every render as a command line
 * (jobs.txt, with slurm.sh for a job array and assemble.sh), and --assemble DIR reads their images back
 * as the renders of the bench. Part of libmurklab. */
#include "lab/bench.h"

#include "cmd/cmd.h"
#include "image/image.h"
#include "util/atomic.h"
#include "util/util.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *const counter_names[MURK_NCOUNTERS] = MURK_COUNTER_NAMES;

/* Where job (variant v, budget bi, seed k) writes its image; v < 0: reference chunk k. */
void murk_bench_job_out(const bench *b, int v, int bi, int k, char *buf, size_t n)
{
    if (v < 0)
        snprintf(buf, n, "%s/renders/ref%d.exr", b->jobs, k);
    else
        snprintf(buf, n, "%s/renders/v%d-b%d-s%d.exr", b->jobs, v, bi, k);
}

/* The value of "NAME": N in a murk:counters JSON text (0 if absent). */
static uint64_t json_u64(const char *json, const char *name)
{
    char key[64];
    snprintf(key, sizeof key, "\"%s\": ", name);
    const char *p = json ? strstr(json, key) : NULL;
    return p ? strtoull(p + strlen(key), NULL, 10) : 0;
}

/* A job's image read back as murk_render_err would have returned it: pixels, spp, seconds, rays, the
 * counters' totals (as one medium), NaN count and largest sample. 0, or -1 after a message naming it. */
int murk_bench_read_job(const char *path, int w, int h, murk_render_result *res)
{
    murk_image im = {0};
    char err[1024];
    memset(res, 0, sizeof *res);
    if (murk_exr_read(path, &im, err, sizeof err) != 0 || im.w != w || im.h != h ||
        !murk_image_meta(&im, "murk:counters") || strcmp(murk_image_meta(&im, "murk:interrupted"), "no") != 0) {
        fprintf(stderr, "murk: %s\nmurk: %s: not the finished %dx%d render of its job (run it again: the line "
                "of jobs.txt that writes it)\n", im.rgb ? "" : err, murk_cli_q(path), w, h);
        murk_image_free(&im);
        return -1;
    }
    const char *json = murk_image_meta(&im, "murk:counters"), *total = strstr(json, "\"total\": ");
    uint64_t t[MURK_NCOUNTERS];
    for (int k = 0; k < MURK_NCOUNTERS; k++)
        t[k] = json_u64(total, counter_names[k]);
    res->media[0] = (murk_counters){t[0], t[1], t[2], t[3], t[4]};
    res->nmedia = 1;
    res->rays = json_u64(json, "rays");
    res->spp = atoi(murk_image_meta(&im, "murk:spp"));
    res->seconds = strtod(murk_image_meta(&im, "murk:render_time"), NULL);
    res->nonfinite = strtoull(murk_image_meta(&im, "murk:nonfinite_samples"), NULL, 10);
    const char *mx = murk_image_meta(&im, "murk:max_sample");
    res->max_sample = mx ? strtod(mx, NULL) : 0.0;
    res->width = w, res->height = h;
    res->rgb = im.rgb;
    im.rgb = NULL;
    murk_image_free(&im);
    return 0;
}

/* " WORD" as a POSIX shell reads it back: plain, or in single quotes. */
void murk_bench_shell_word(FILE *f, const char *w)
{
    int plain = *w != 0;
    for (const char *p = w; *p; p++)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_=.,/:+@%", *p))
            plain = 0;
    if (plain) {
        fprintf(f, " %s", w);
        return;
    }
    fputs(" '", f);
    for (const char *p = w; *p; p++)
        fputs(*p == '\'' ? "'\\''" : (char[2]){*p, 0}, f);
    fputc('\'', f);
}

/* One render as a command line of jobs.txt. */
static void emit_job(const bench *b, FILE *jobs, const char *murk, const char *scene, const char *const *sets,
                     size_t n, double budget, const char *out)
{
    char num[64], *line = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&line, &len);
    if (!f) {
        fprintf(stderr, "murk: out of memory\n");
        exit(1);
    }
    murk_bench_shell_word(f, murk);
    fputs(" render", f);
    murk_bench_shell_word(f, scene);
    for (size_t i = 0; i < n; i++) {
        fputs(" --set", f);
        murk_bench_shell_word(f, sets[i]);
    }
    if (b->time_mode && budget > 0) {
        snprintf(num, sizeof num, "%g", budget);
        fprintf(f, " --time %s --spp %d", num, 1 << 24);
    } else {
        fprintf(f, " --spp %d", (int)budget);
    }
    if (b->threads)
        fprintf(f, " --threads %d", b->threads);
    fputs(" --quiet -o", f);
    murk_bench_shell_word(f, out);
    fclose(f);
    fprintf(jobs, "%s\n", line + 1); /* without murk_bench_shell_word's leading space */
    free(line);
}

/* jobs.txt: every render of the bench, the reference's chunks first, as one command line each that
 * writes its image where murk_bench_job_out says (b->jobs: the jobs' folder, absolute). The count. */
static int jobs_txt(const bench *b, FILE *f, const char *murk, const char *scene)
{
    char out[8192];
    const char **sets = murk_xmalloc(murk_bench_max_sets(b) * sizeof *sets);
    char *store[BENCH_STORE];
    size_t nstore = 0;
    int njobs = 0;
    for (int c = 0; c < REF_CHUNKS && !b->reference; c++) {
        char seed[40];
        size_t n = murk_bench_sets(b, -1, -1, sets, store, &nstore);
        snprintf(seed, sizeof seed, "render.seed=%d", 900001 + c);
        sets[n++] = seed;
        murk_bench_job_out(b, -1, 0, c, out, sizeof out);
        emit_job(b, f, murk, scene, sets, n, (b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS, out);
        murk_bench_free_sets(store, &nstore);
        njobs++;
    }
    for (int bi = 0; bi < b->nbudgets; bi++)
        for (int k = 0; k < b->repeat; k++)
            for (int v = 0; v < b->nvariants; v++) {
                size_t n = murk_bench_sets(b, v, 1 + k, sets, store, &nstore);
                murk_bench_job_out(b, v, bi, k, out, sizeof out);
                emit_job(b, f, murk, scene, sets, n, b->budgets[bi], out);
                murk_bench_free_sets(store, &nstore);
                njobs++;
            }
    free(sets);
    return njobs;
}

/* assemble.sh: the bench's own command line, in its folder, with --assemble DIR for --emit-jobs DIR. */
static void assemble_sh(FILE *f, const char *murk, const char *dir, int argc, char **argv)
{
    char cwd[4096];
    fprintf(f, "#!/bin/sh\n# Reads the renders of jobs.txt back into bench.csv, the charts and the report: the\n"
               "# bench's own command line, in its folder, with --assemble for --emit-jobs.\ncd");
    murk_bench_shell_word(f, getcwd(cwd, sizeof cwd) ? cwd : ".");
    fputs(" || exit 1\nexec", f);
    murk_bench_shell_word(f, murk);
    fputs(" bench", f);
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--emit-jobs")) {
            fputs(" --assemble", f);
            murk_bench_shell_word(f, dir);
            i++;
        } else {
            murk_bench_shell_word(f, argv[i]);
        }
    }
    fputc('\n', f);
}

/* --emit-jobs DIR: every render of the bench (the reference's chunks first) as one line of DIR/jobs.txt,
 * DIR/slurm.sh running line SLURM_ARRAY_TASK_ID + 1 as one task of a job array, and DIR/assemble.sh,
 * this bench's command line with --assemble DIR, which reads the images back into bench.csv, the
 * charts and the report as if the renders had run here. The jobs' paths are absolute. */
int murk_bench_emit_jobs(const bench *b, int argc, char **argv)
{
    char murk[4096], scene[4096], dir[4096], path[8192];
    ssize_t l = readlink("/proc/self/exe", murk, sizeof murk - 1);
    if (l <= 0 || !realpath(b->scene, scene)) {
        fprintf(stderr, "murk: cannot resolve the paths of murk and %s\n", murk_cli_q(b->scene));
        return 1;
    }
    murk[l] = 0;
    snprintf(path, sizeof path, "%s/renders", b->jobs);
    if (murk_bench_mkdirs(path) != 0 || !realpath(b->jobs, dir)) {
        fprintf(stderr, "murk: cannot create %s: %s\n", murk_cli_q(path), strerror(errno));
        return 1;
    }
    bench jb = *b;
    jb.jobs = dir;
    /* the three files as text in memory, then written as one group (atomic.h): all of them or none */
    enum { JOBS, SLURM, ASSEMBLE, NFILES };
    static const char *const names[NFILES] = {"jobs.txt", "slurm.sh", "assemble.sh"};
    char *text[NFILES] = {NULL, NULL, NULL};
    size_t len[NFILES] = {0, 0, 0};
    int njobs = 0, bad = 0;
    for (int i = 0; i < NFILES && !bad; i++) {
        FILE *f = open_memstream(&text[i], &len[i]);
        if (!f) {
            bad = 1;
            break;
        }
        if (i == JOBS)
            njobs = jobs_txt(&jb, f, murk, scene);
        else if (i == SLURM)
            fprintf(f, "#!/bin/sh\n"
                       "# murk bench as a Slurm job array: one render per task (line TASK + 1 of jobs.txt).\n"
                       "#   jid=$(sbatch --parsable slurm.sh)\n"
                       "#   sbatch --dependency=afterok:$jid --wrap 'sh %s/assemble.sh'\n"
                       "#SBATCH --job-name=murk-bench\n#SBATCH --array=0-%d\n"
                       "exec sh -c \"$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" '%s/jobs.txt')\"\n", dir, njobs - 1,
                    dir);
        else
            assemble_sh(f, murk, dir, argc, argv);
        bad = fclose(f) != 0;
    }
    char err[8400] = "out of memory";
    if (!bad) {
        murk_output_begin();
        for (int i = 0; i < NFILES && !bad; i++) {
            text_job tj = {text[i], len[i]};
            snprintf(path, sizeof path, "%s/%s", dir, names[i]);
            bad = murk_write_atomic(path, murk_bench_text_fill, &tj, err, sizeof err) != 0;
        }
        if (bad)
            murk_output_abort();
        else
            bad = murk_output_commit(err, sizeof err) != 0;
    }
    for (int i = 0; i < NFILES; i++)
        free(text[i]);
    if (bad) {
        fprintf(stderr, "murk: %s\n", err);
        return 1;
    }
    printf("%d renders as jobs: %s/jobs.txt (one command a line), %s/slurm.sh (sbatch: a job array); then "
           "sh %s/assemble.sh\n", njobs, dir, dir, dir);
    return 0;
}
