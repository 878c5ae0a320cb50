/* mpi.c — murk's MPI calls (mpi_job.h); stubs of a job of one rank when built without MPI (MURK_HAVE_MPI
 * undefined). Sends are nonblocking (MPI_Isend from a buffer freed once delivered), so two ranks
 * sending to each other at once never wait for each other whatever the transport's eager limit. Every
 * wait (a broadcast, a sum, the sends' delivery) tests and sleeps 0.2 ms between tests instead of
 * blocking in MPI: Open MPI's blocking calls spin, and a rank spinning at the end of a pass would take
 * a core from the render threads of a rank sharing its machine. */
#include "render/mpi_job.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifdef MURK_HAVE_MPI
#include <mpi.h>
#endif

static int g_rank, g_size = 1, g_init;

MURK_API int murk_mpi_built(void)
{
#ifdef MURK_HAVE_MPI
    return 1;
#else
    return 0;
#endif
}

MURK_API int murk_mpi_launched(void)
{
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++)
        if (getenv(vars[i]))
            return 1;
    return 0;
}

MURK_API int murk_mpi_rank(void) { return g_rank; }
MURK_API int murk_mpi_size(void) { return g_size; }

MURK_API const char *murk_mpi_host(void)
{
    static char host[256];
    if (!host[0] && gethostname(host, sizeof host - 1) != 0)
        snprintf(host, sizeof host, "?");
    return host;
}

#ifdef MURK_HAVE_MPI

/* Waits for r, sleeping between tests. */
static void wait_for(MPI_Request *r)
{
    for (;;) {
        int done = 0;
        MPI_Test(r, &done, MPI_STATUS_IGNORE);
        if (done)
            return;
        struct timespec ts = {0, 200 * 1000};
        nanosleep(&ts, NULL);
    }
}

typedef struct pending {
    MPI_Request req;
    void *buf;
} pending;
static pending *g_pend;
static size_t g_npend, g_cap;

MURK_API int murk_mpi_init(char *err, size_t errlen)
{
    if (g_init || !murk_mpi_launched())
        return g_size;
    int provided = 0, ok = 0;
    MPI_Initialized(&ok);
    if (!ok && MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        murk_snprintf(err, errlen, "MPI_Init failed: rendering as a single process");
        return 1;
    }
    g_init = 1;
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    return g_size;
}

MURK_API void murk_mpi_finalize(void)
{
    if (!g_init)
        return;
    murk_mpi_flush();
    free(g_pend);
    g_pend = NULL;
    g_npend = g_cap = 0;
    MPI_Finalize();
    g_init = 0;
    g_rank = 0;
    g_size = 1;
}

MURK_API void murk_mpi_abort(int status)
{
    if (g_init)
        MPI_Abort(MPI_COMM_WORLD, status);
    exit(status);
}

MURK_API int murk_mpi_agree(int ok, char *msg, size_t msglen, int *who)
{
    *who = ok ? -1 : g_rank;
    if (g_size < 2)
        return !ok;
    int *oks = malloc((size_t)g_size * sizeof *oks);
    if (!oks)
        murk_mpi_abort(1);
    ok = ok != 0;
    MPI_Allgather(&ok, 1, MPI_INT, oks, 1, MPI_INT, MPI_COMM_WORLD);
    int bad = 0, first = -1;
    for (int r = 0; r < g_size; r++)
        if (!oks[r]) {
            bad++;
            if (first < 0)
                first = r;
        }
    free(oks);
    *who = first;
    if (first > 0) { /* its message to rank 0 */
        int len = (int)(msglen > 0 ? msglen : 1);
        if (g_rank == first)
            MPI_Send(msg, len, MPI_CHAR, 0, MURK_TAG_MSG, MPI_COMM_WORLD);
        else if (g_rank == 0) {
            MPI_Recv(msg, len, MPI_CHAR, first, MURK_TAG_MSG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            msg[msglen - 1] = 0;
        }
    }
    return bad;
}

MURK_API void murk_mpi_bcast(void *buf, size_t n)
{
    MPI_Request r;
    if (g_size < 2)
        return;
    MPI_Ibcast(buf, (int)n, MPI_BYTE, 0, MPI_COMM_WORLD, &r);
    wait_for(&r);
}

void murk_mpi_sum_u64(uint64_t *v, int n)
{
    MPI_Request r;
    if (g_size < 2)
        return;
    if (g_rank == 0)
        MPI_Ireduce(MPI_IN_PLACE, v, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD, &r);
    else
        MPI_Ireduce(v, NULL, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD, &r);
    wait_for(&r);
}

void murk_mpi_max_double(double *v)
{
    MPI_Request r;
    if (g_size < 2)
        return;
    if (g_rank == 0)
        MPI_Ireduce(MPI_IN_PLACE, v, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD, &r);
    else
        MPI_Ireduce(v, NULL, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD, &r);
    wait_for(&r);
}

/* Frees the buffers of the sends that have been delivered. */
static void reap(void)
{
    size_t k = 0;
    for (size_t i = 0; i < g_npend; i++) {
        int done = 0;
        MPI_Test(&g_pend[i].req, &done, MPI_STATUS_IGNORE);
        if (done)
            free(g_pend[i].buf);
        else
            g_pend[k++] = g_pend[i];
    }
    g_npend = k;
}

void murk_mpi_post(int dest, int tag, void *buf, size_t n)
{
    reap();
    if (g_npend == g_cap) {
        g_cap = g_cap ? 2 * g_cap : 64;
        g_pend = murk_xrealloc(g_pend, g_cap * sizeof *g_pend);
    }
    g_pend[g_npend].buf = buf;
    MPI_Isend(buf, (int)n, MPI_BYTE, dest, tag, MPI_COMM_WORLD, &g_pend[g_npend].req);
    g_npend++;
}

int murk_mpi_poll(int src, int *from, int *tag, size_t *n)
{
    int flag = 0, count = 0;
    MPI_Status st;
    reap();
    MPI_Iprobe(src < 0 ? MPI_ANY_SOURCE : src, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag)
        return 0;
    MPI_Get_count(&st, MPI_BYTE, &count);
    *from = st.MPI_SOURCE;
    *tag = st.MPI_TAG;
    *n = (size_t)count;
    return 1;
}

void murk_mpi_recv(int from, int tag, void *buf, size_t n)
{
    MPI_Recv(buf, (int)n, MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

void murk_mpi_flush(void)
{
    for (size_t i = 0; i < g_npend; i++) {
        wait_for(&g_pend[i].req);
        free(g_pend[i].buf);
    }
    g_npend = 0;
}

#else /* built without MPI: a job of one rank */

MURK_API int murk_mpi_init(char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    (void)g_init;
    return 1;
}
MURK_API void murk_mpi_finalize(void) {}
MURK_API void murk_mpi_abort(int status) { exit(status); }
MURK_API int murk_mpi_agree(int ok, char *msg, size_t msglen, int *who)
{
    (void)msg;
    (void)msglen;
    *who = ok ? -1 : 0;
    return !ok;
}
MURK_API void murk_mpi_bcast(void *buf, size_t n)
{
    (void)buf;
    (void)n;
}
void murk_mpi_sum_u64(uint64_t *v, int n)
{
    (void)v;
    (void)n;
}
void murk_mpi_max_double(double *v) { (void)v; }
void murk_mpi_post(int dest, int tag, void *buf, size_t n)
{
    (void)dest;
    (void)tag;
    (void)n;
    free(buf);
}
int murk_mpi_poll(int src, int *from, int *tag, size_t *n)
{
    (void)src;
    (void)from;
    (void)tag;
    (void)n;
    return 0;
}
void murk_mpi_recv(int from, int tag, void *buf, size_t n)
{
    (void)from;
    (void)tag;
    (void)buf;
    (void)n;
}
void murk_mpi_flush(void) {}

#endif
