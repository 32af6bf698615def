/*
 * bvh_internal.h: what the BVH reader (bvhread.c) shares with the writer
 * (bvhwrite.c), which uses the reader's number and layout rules so that a
 * written BVH reads back as written. Not installed.
 */
#ifndef MLOD_BVH_INTERNAL_H
#define MLOD_BVH_INTERNAL_H

#include <stddef.h>

#include "model/mlod_model.h"

#define BVH_MAX_FRAMES 10000000       /* more frames than this is absurd */
#define BVH_MAX_JOINTS (1 << 20)
#define BVH_MAX_WRITE_VALUES 200000000 /* values a written BVH may hold */

/* The channel keywords, in the order of mlod_bvh_channel (MLOD_BVH_XPOS
 * first). */
extern const char *const bvh_channel_names[6];

/* The Euler order of a channel layout: the order in which its rotation
 * channels appear, the missing axes appended in x, y, z order; fallback
 * when there is no rotation channel. */
mlod_euler_order bvh_layout_euler(const unsigned char *ch, int n, mlod_euler_order fallback);

/* 10^e for 0 <= e <= 22, exactly. */
double bvh_pow10_exact(int e);

/* A whole token as a decimal number: strtod's value in the C locale
 * (decimal.c); BVH_NUM_RANGE beyond the float range. */
enum { BVH_NUM_OK, BVH_NUM_SYNTAX, BVH_NUM_NONFINITE, BVH_NUM_RANGE };
int bvh_parse_number(const char *s, size_t len, double *out);

#endif
