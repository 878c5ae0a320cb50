/* obj.h — Wavefront OBJ triangle meshes. Internal to libmurk.
 * Reads v, vt, vn and f (polygons are fan-triangulated; negative indices count from the end;
 * v/vt/vn, v//vn and v/vt forms); vertices are unified per distinct (v, vt, vn) triple. Other
 * statements (o, g, s, usemtl, mtllib, l, p, comments) are ignored. Errors are
 * "path:line:col: what is wrong", returned as -1; nothing is leaked on failure. */
#ifndef MURK_OBJ_H
#define MURK_OBJ_H

#include <stddef.h>
#include <stdint.h>

typedef struct murk_mesh {
    uint32_t nverts, ntris;
    float *pos;     /* 3*nverts */
    float *uv;      /* 2*nverts, or NULL when the file has no vt */
    float *nrm;     /* 3*nverts, or NULL when the file has no vn */
    uint32_t *idx;  /* 3*ntris */
} murk_mesh;

int murk_obj_load(const char *path, murk_mesh *mesh, char *err, size_t errlen);
void murk_mesh_free(murk_mesh *mesh);

#endif
