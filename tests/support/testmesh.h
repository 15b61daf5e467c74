/* testmesh.h — meshes the tests generate, with known closed forms:
 * an icosphere (radius 1, closed, genus 0), a stretched sphere, a torus (radii R, r, closed,
 * genus 1) and a flat open disk (radius 1, one boundary loop); and a real
 * mesh of ../shared/data read for a test; the identity map of a mesh.
 * Test code only: never linked
 * into the engine. Caller frees with mesh_free. */
#ifndef TESTMESH_H
#define TESTMESH_H
#include "mesh/mesh.h"
#include "map/bmap.h"

/* Subdivided icosahedron projected to the unit sphere: 10*4^level + 2 vertices. */
mesh *testmesh_icosphere(int level);
/* Torus around the z axis, nu segments around the axis, nv around the tube. */
mesh *testmesh_torus(double R, double r, int nu, int nv);
/* A closed tube along z of the given length: rings of `around` vertices
 * at z = length·k/(rings+1), k = 1..rings, of radius sin(π k/(rings+1)),
 * and a pole at each end (the meridian of a sphere, stretched along z).
 * Two with the same rings and around have the same connectivity. */
mesh *testmesh_spheroid(double length, int rings, int around);
/* Flat disk in the z = 0 plane, rings concentric rings around the centre. */
mesh *testmesh_disk(int rings);
/* The mirror image of m through the plane x = 0 with every face's corner
 * order reversed, so that the normals stay outward (a proper mesh, not an
 * inside-out one); vertex i is vertex i of m reflected. */
mesh *testmesh_mirrored(const mesh *m);
/* m with every triangle split into four at its edge midpoints (the
 * geometry is unchanged): vertices 0..nv-1 are m's, then one per edge in
 * the order the faces first meet them, so two meshes with the same
 * connectivity give two with the same connectivity (an identity ground
 * truth stays one). Faces keep m's orientation. NULL when out of memory. */
mesh *testmesh_subdivided(const mesh *m);
/* The mesh at rel under the data folder (harness_data_path); the test
 * fails with mesh_read's message when it cannot be read. */
mesh *testmesh_read(const char *rel);
/* Each vertex of X onto the same vertex of a mesh with X's faces (its
 * row: a face of X holding it, weight 1 at that corner); NULL when out of
 * memory. Caller frees with bmap_free. */
bmap *testmesh_identity(const mesh *X);
/* The mean length of each face's first edge. */
double testmesh_mean_edge(const mesh *X);
/* Deterministic pseudo-random numbers in [0, 1) for tests (xorshift). */
double testmesh_rand(unsigned long long *state);

#endif
