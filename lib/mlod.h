/*
 * mlod.h: the whole public API of libmlod, the bake library of mlod, as one
 * umbrella over the headers of its parts. Tools include this; the library's
 * own files include only the part headers they use.
 *
 * mlod implements "Multi-Layer Level of Detail for Character Animation"
 * (Savoye & Meyer, VRIPHYS 2008). Dependencies run one way, top to bottom:
 *
 *   core/mlod_core.h          results, errors, math (shared with the runtime)
 *   model/mlod_model.h        the character model, pose, skinning
 *   io/mlod_io.h              glTF (C shim over tinygltf), BVH, format detection
 *   measure/mlod_measure.h    surface, posed, vertex and joint deviation, bound search
 *   skeleton/mlod_skeleton.h  labels, energy, MSG, skeleton levels (4.1)
 *   mesh/mlod_mesh.h          BindGraphMesh, collapses, Power Skinning (4.2)
 *   motion/mlod_motion.h      motion tree, key reduction, weight tracks (4.3)
 *   record/mlod_record.h      the stage record, extras.mlod (mlod-record(5))
 *   pack/mlod_pack_write.h    the .mlod pack writer (mlod(5); layout in rt/mlod_pack.h)
 *
 * The runtime (lib/rt, header mlod_rt.h) builds from core alone and does
 * not include this header.
 */
#ifndef MLOD_H
#define MLOD_H

#include "mlod_core.h"
#include "model/mlod_model.h"
#include "io/mlod_io.h"
#include "measure/mlod_measure.h"
#include "skeleton/mlod_skeleton.h"
#include "mesh/mlod_mesh.h"
#include "motion/mlod_motion.h"
#include "record/mlod_record.h"
#include "pack/mlod_pack_write.h"

#endif /* MLOD_H */
