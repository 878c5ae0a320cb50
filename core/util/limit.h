/* limit.h — every limit murk enforces on untrusted input, in one place. Internal to libmurk.
 *
 * Sizes that decide an allocation have a default and can be raised (or lowered) for one run with an
 * environment variable of the same name holding a whole number, e.g. MURK_MAX_IMAGE_PIXELS=268435456.
 * A malformed value is ignored with a warning. README.md ("Limits") lists them all.
 *
 * The numeric ranges below are fixed: they follow what float arithmetic and Embree can carry. */
#ifndef MURK_LIMIT_H
#define MURK_LIMIT_H

#include <stdint.h>

typedef enum murk_limit_id {
    MURK_LIMIT_IMAGE_PIXELS,   /* pixels of an image read (texture, compare) or rendered: 2^26 */
    MURK_LIMIT_GRID_VOXELS,    /* voxels of a density grid (.vol, baked cloud) or stored in a sparse one's bricks: 2^27 */
    MURK_LIMIT_FILE_BYTES,     /* bytes of one input file (OBJ mesh, density grid): 2^30 */
    MURK_LIMIT_MESH_TRIANGLES, /* triangles of one mesh (OBJ, or all of an asset's): 2^26 */
    MURK_LIMIT_PAGE_BYTES,     /* image data of a comparison page (report.html), base64 bytes: 2^26 */
    MURK_LIMIT_GRID_BOX,       /* voxels of a sparse grid's (.vdb, .nvdb) index box: 2^40 */
    MURK_LIMIT_COUNT
} murk_limit_id;

/* The limit in force (the default, or its environment override). */
uint64_t murk_limit(murk_limit_id id);
/* The environment variable that overrides it ("MURK_MAX_IMAGE_PIXELS", ...). */
const char *murk_limit_name(murk_limit_id id);

/* Largest |coordinate| of any point of the scene (camera, shapes after their transform, media boxes):
 * Embree refuses ray origins beyond 1.8e18 (an assertion), and float arithmetic on a scene near
 * that size has no precision left. */
#define MURK_MAX_COORD 1e15
/* Largest optical depth (extinction x majorant density x majorant_factor x extent) of a medium
 * across its density box (a grid) or across the scene (a constant density). Beyond it the mean free
 * flight falls below ~16 float spacings of the ray distance t and tracking stops advancing. */
#define MURK_MAX_OPTICAL_DEPTH 1e6
/* Decoded size of a compressed image over its file size (deflate cannot exceed 1032:1; EXR's PXR24
 * stores 3 bytes per float before deflate). A header claiming more is lying. */
#define MURK_MAX_EXPANSION 4096.0

#endif
