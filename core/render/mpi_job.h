/* mpi_job.h — the few MPI calls murk makes, behind functions that need no MPI header (mpi.c). Not
 * named mpi.h: that would shadow Open MPI's <mpi.h> on the include path. Internal to
 * libmurk; the MURK_API ones serve the murk command.
 *
 * Built with -Dmpi=enabled (the default when Open MPI's pkg-config file is found), murk joins an MPI
 * job only when a launcher started it (mpirun/srun set OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_RANK):
 * a plain `murk render` never initialises MPI and behaves as a build without it. Built without MPI,
 * every function is a stub of a job of one rank. Only the calling (main) thread ever calls MPI
 * (MPI_THREAD_FUNNELED); the render threads never do. Ranks are assumed to be one kind of machine (the
 * messages are raw bytes, native byte order). */
#ifndef MURK_MPI_H
#define MURK_MPI_H

#include <stddef.h>
#include <stdint.h>
#include "util/util.h"

/* Message tags of the tile protocol (render.c). */
enum { MURK_TAG_REQ = 1, MURK_TAG_TILE, MURK_TAG_END, MURK_TAG_RESULT, MURK_TAG_MSG };

/* Joins the MPI job if a launcher started this process and murk was built with MPI; otherwise (and on
 * failure, with a message in err) stays a job of one. Returns the number of ranks. */
MURK_API int murk_mpi_init(char *err, size_t errlen);
MURK_API void murk_mpi_finalize(void);
MURK_API int murk_mpi_rank(void);
MURK_API int murk_mpi_size(void);
/* 1 when murk was built with MPI; 1 when a launcher seems to have started this process. */
MURK_API int murk_mpi_built(void);
MURK_API int murk_mpi_launched(void);
/* Ends every rank of the job at once (MPI_Abort); never returns. */
MURK_API void murk_mpi_abort(int status);

/* Collective. Every rank says whether it is fine (ok) and, if not, why (msg). Returns the number of
 * ranks that are not; then *who is the lowest of them and, on rank 0, msg holds its message (rank 0's
 * own when it is one of them). */
MURK_API int murk_mpi_agree(int ok, char *msg, size_t msglen, int *who);
/* Collective: rank 0's n bytes to every rank. */
MURK_API void murk_mpi_bcast(void *buf, size_t n);
/* Collective: n integers summed over the ranks into rank 0's v (exact, in any order). */
void murk_mpi_sum_u64(uint64_t *v, int n);
/* Collective: the largest of every rank's *v into rank 0's *v. */
void murk_mpi_max_double(double *v);
/* The name of this host (for messages). */
MURK_API const char *murk_mpi_host(void);

/* Point to point. post sends n bytes of buf (taken over, freed when delivered) without blocking;
 * poll says whether a message from src (-1: anyone) is waiting and its source, tag and size; recv
 * receives it; flush waits until everything posted is delivered. */
void murk_mpi_post(int dest, int tag, void *buf, size_t n);
int murk_mpi_poll(int src, int *from, int *tag, size_t *n);
void murk_mpi_recv(int from, int tag, void *buf, size_t n);
void murk_mpi_flush(void);

#endif
