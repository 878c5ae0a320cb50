/* scene.c — the scene data: what a loaded scene owns and how it is released (load.c builds it). */
#include "scene.h"
#include "media.h"
#include "texture.h"
#include "util.h"

#include <stdlib.h>

void murk_shape_free(murk_shape *sh)
{
    free(sh->pos);
    free(sh->uv);
    free(sh->nrm);
    free(sh->ng);
    free(sh->idx);
    free(sh->name);
}

MURK_API void murk_scene_free(murk_scene *s)
{
    if (!s)
        return;
    if (s->rtc)
        rtcReleaseScene(s->rtc);
    if (s->device)
        rtcReleaseDevice(s->device);
    if (s->integrator && s->integrator_vt)
        s->integrator_vt->destroy(s->integrator);
    for (size_t i = 0; i < s->nmaterials; i++) {
        s->materials[i].m.vt->destroy(s->materials[i].m.self);
        free(s->materials[i].name);
    }
    free(s->materials);
    murk_media_free(s);
    for (size_t i = 0; i < s->nshapes; i++)
        murk_shape_free(&s->shapes[i]);
    free(s->shapes);
    for (size_t i = 0; i < s->ntextures; i++)
        murk_texture_free(s->textures[i]);
    free(s->textures);
    for (size_t i = 0; i < s->nparam_store; i++)
        free(s->param_store[i]);
    free(s->param_store);
    free(s->lights);
    free(s->light_cdf);
    murk_registry_free(&s->reg);
    murk_ydoc_free(&s->doc);
    free(s);
}
