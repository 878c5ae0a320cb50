/* source.h — a scalar field from a scene block: the one reader of a medium's fields (its density, and the
 * other fields a medium names the same way). Internal to libmurk.
 *
 *   { constant: V }                        V >= 0 everywhere
 *   { grid: F.vol }  { grid: F.nvdb }      a Mitsuba .vol (dense) or a NanoVDB file's first float grid (sparse)
 *   { vdb: F.vdb, grid: NAME }             the grid NAME of an OpenVDB file (sparse); grid may be left out
 *                                          when the file holds one grid
 *   { cloud: { min, max, seed, frequency, octaves, coverage, resolution } }   the procedural cloud
 *
 * Paths are relative to the scene file. */
#ifndef MURK_SOURCE_H
#define MURK_SOURCE_H

#include <stddef.h>

#include "media/density.h"
#include "yaml/yamldoc.h"

/* The field the block n describes; `what` names the block in messages ("density", "temperature", ...).
 * NULL with a located error ("scene.yaml:12:7: density: cloud.vdb: no grid 'dens'; the file has
 * 'density', 'temperature'"). */
murk_field *murk_field_from_node(const char *scene_file, const murk_ynode *n, const char *what, char *err,
                                 size_t errlen);
/* The file a field block reads (its `vdb` or `grid` file, relative to the scene file as written), or NULL
 * for a constant or a cloud: what a checkpoint's content hash folds in. */
const murk_ynode *murk_field_node_file(const murk_ynode *n);

#endif
