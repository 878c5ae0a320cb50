/* accel.c — the Embree 3 scene: triangle geometry for quads, boxes and meshes; Embree's analytic
 * point-spheres for spheres. Geometry ids equal shape indices. */
#include "render/accel.h"
#include "util/error.h"
#include "util/runtime.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void embree_error(void *user, enum RTCError code, const char *str)
{
    (void)user;
    murk_log(MURK_LOG_WARN, "embree error %d: %s", (int)code, str ? str : "");
}

/* Embree's memory monitor: what it allocates and frees for the scene (called from its build threads). */
static bool embree_memory(void *user, ssize_t bytes, bool post)
{
    (void)post;
    __atomic_fetch_add(&((murk_scene *)user)->embree_bytes, (long long)bytes, __ATOMIC_RELAXED);
    return true;
}

int murk_accel_build(murk_scene *s, char *err, size_t errlen)
{
    s->device = rtcNewDevice(NULL);
    if (!s->device) {
        murk_err_file(err, errlen, s->doc.file, "cannot create an Embree device (error %d)", (int)rtcGetDeviceError(NULL));
        return -1;
    }
    rtcSetDeviceErrorFunction(s->device, embree_error, NULL);
    s->embree_bytes = 0;
    rtcSetDeviceMemoryMonitorFunction(s->device, embree_memory, s);
    s->rtc = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    /* render.traversal: Embree's default unless the scene asks for its robust mode (README.md, "Scene format") */
    rtcSetSceneFlags(s->rtc, s->traversal == MURK_TRAVERSAL_ROBUST ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    s->nboundaries = 0;
    for (size_t i = 0; i < s->nshapes; i++) {
        murk_shape *sh = &s->shapes[i];
        s->nboundaries += !sh->material;
        RTCGeometry g;
        if (sh->type == MURK_SHAPE_SPHERE) {
            g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
            float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1);
            v[0] = sh->center.x, v[1] = sh->center.y, v[2] = sh->center.z, v[3] = sh->radius;
        } else {
            g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
            /* Embree reads 16 bytes past the last vertex: shared buffers need that padding. */
            float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                               sh->nverts);
            uint32_t *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                                   sh->ntris);
            if (!v || !ix) {
                rtcReleaseGeometry(g);
                murk_err_file(err, errlen, s->doc.file, "Embree could not allocate geometry for shape %zu", i);
                return -1;
            }
            memcpy(v, sh->pos, 3u * sh->nverts * sizeof(float));
            memcpy(ix, sh->idx, 3u * sh->ntris * sizeof(uint32_t));
            /* each triangle's unit normal as host.c's fill_hit() computed it per hit (same operations,
             * so the same floats): one load there instead of a cross product and a normalisation */
            free(sh->ng);
            sh->ng = murk_xmalloc(3u * sh->ntris * sizeof(float));
            for (uint32_t t = 0; t < sh->ntris; t++) {
                const uint32_t *tv = &sh->idx[3 * t];
                murk_vec3 n = murk_triangle_normal(murk_shape_vertex(sh, tv[0]), murk_shape_vertex(sh, tv[1]),
                                                   murk_shape_vertex(sh, tv[2]));
                sh->ng[3 * t] = n.x, sh->ng[3 * t + 1] = n.y, sh->ng[3 * t + 2] = n.z;
            }
        }
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(s->rtc, g);
        rtcReleaseGeometry(g);
        if (id != i) {
            murk_err_file(err, errlen, s->doc.file, "internal error: Embree geometry id %u for shape %zu", id, i);
            return -1;
        }
    }
    rtcCommitScene(s->rtc);
    if (rtcGetDeviceError(s->device) != RTC_ERROR_NONE) {
        murk_err_file(err, errlen, s->doc.file, "Embree failed to build the scene");
        return -1;
    }
    return 0;
}
