/* free.c — what a loaded scene owns and how it is released: murk_scene_free, the inverse of load.c's
 * murk_scene_load (the scene's data, scene.h, sits below the media and render parts it frees). */
#include "load/load.h"
#include "media/media.h"
#include "render/envmap.h"
#include "scene/texture.h"
#include "util/runtime.h"
#include "util/util.h"

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
    murk_warn_forget(s);
    free(s->empty_shapes);
    free(s->few_spheres);
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
    for (size_t i = 0; i < s->nasset_materials; i++) {
        s->asset_materials[i]->m.vt->destroy(s->asset_materials[i]->m.self);
        free(s->asset_materials[i]->name);
        free(s->asset_materials[i]);
        murk_ydoc_free(s->asset_docs[i]);
        free(s->asset_docs[i]);
    }
    free(s->asset_materials);
    free(s->asset_docs);
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
    free(s->added);
    for (size_t i = 0; i < s->nlight_origins; i++)
        free(s->light_origins[i].where);
    free(s->light_origins);
    for (size_t i = 0; i < s->nasset_inputs; i++)
        free(s->asset_inputs[i]);
    free(s->asset_inputs);
    free(s->env);
    for (size_t i = 0; i < s->nenvmaps; i++)
        murk_envmap_free(s->envmaps[i]);
    free(s->envmaps);
    murk_registry_free(&s->reg);
    murk_ydoc_free(&s->doc);
    free(s);
}
