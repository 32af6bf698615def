/*
 * meshnote.c: the notes of a mesh levels run (L->notes, "; "-separated),
 * appended by meshlevels.c, influence.c and lodgltf.c. Its own file so that
 * those three call down into it and never into each other in a circle.
 */
#include <stdio.h>
#include <string.h>

#include "meshlevels.h"

void mlod_mesh_note_(mlod_mesh_levels *L, const char *text)
{
	size_t n = strlen(L->notes);
	if (n + 4 >= sizeof L->notes)
		return;
	if (n)
		n += (size_t)snprintf(L->notes + n, sizeof L->notes - n, "; ");
	snprintf(L->notes + n, sizeof L->notes - n, "%s", text);
}
