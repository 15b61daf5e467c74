// ctf_decimate.cpp — a decimated copy of a mesh (ctf.h) by OpenMesh's
// decimater: halfedge collapses ordered by the quadric error, refused when
// a face's normal would turn more than CTF_MAX_NORMAL_TURN degrees or a
// face would get thinner than aspect CTF_MIN_ASPECT (RHM's cotan operators
// and the projections want round faces), and never at a kept vertex. A
// halfedge collapse moves no vertex, so every coarse vertex is a vertex of
// the input, in the input's order.
#include "ctf/ctf.h"
extern "C" {
#include "util/errbuf.h"
}

// OpenMesh's property vectors trip g++ 12's -Wmaybe-uninitialized at -O2
// (std::vector of its handle types, inside the library's templates).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModAspectRatioT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

namespace {
struct Traits : OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<Traits> Mesh;
typedef OpenMesh::Decimater::DecimaterT<Mesh> Decimater;

int decimate(const mesh *m, int target_nv, const int *keep, int nkeep, mesh **out,
             int **fine_vertex, char *err, size_t errsz)
{
    Mesh om;
    std::vector<Mesh::VertexHandle> vh((size_t)m->nv);
    for (int v = 0; v < m->nv; v++)
        vh[(size_t)v] = om.add_vertex(Mesh::Point(m->v[3 * v], m->v[3 * v + 1], m->v[3 * v + 2]));
    for (int t = 0; t < m->nf; t++) {
        const int *f = m->f + 3 * t;
        if (!om.add_face(vh[(size_t)f[0]], vh[(size_t)f[1]], vh[(size_t)f[2]]).is_valid())
            return errbuf_set(err, errsz, CTF_EINPUT, "face %d (%d %d %d) is not manifold", t,
                              f[0], f[1], f[2]);
    }
    om.request_vertex_status();
    om.request_edge_status();
    om.request_halfedge_status();
    om.request_face_status();
    om.request_face_normals();
    om.update_face_normals();
    for (int r = 0; r < nkeep; r++)
        om.status(vh[(size_t)keep[r]]).set_locked(true);
    Decimater dec(om);
    OpenMesh::Decimater::ModQuadricT<Mesh>::Handle hq;
    OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle hn;
    OpenMesh::Decimater::ModAspectRatioT<Mesh>::Handle ha;
    dec.add(hq);
    dec.add(hn);
    dec.add(ha);
    dec.module(hq).unset_max_err();
    dec.module(hn).set_max_normal_deviation(CTF_MAX_NORMAL_TURN);
    dec.module(ha).set_aspect_ratio(CTF_MIN_ASPECT);
    dec.module(ha).set_binary(true);
    if (!dec.initialize())
        return errbuf_set(err, errsz, CTF_EFAILED, "the decimater did not start");
    dec.decimate_to((size_t)target_nv);
    int nv = 0, nf = 0;
    std::vector<int> coarse((size_t)m->nv, -1);
    for (int v = 0; v < m->nv; v++)
        if (!om.status(vh[(size_t)v]).deleted())
            coarse[(size_t)v] = nv++;
    for (Mesh::FaceIter f = om.faces_begin(); f != om.faces_end(); ++f)
        nf += !om.status(*f).deleted();
    mesh *c = mesh_new(nv, nf);
    int *fv = (int *)malloc(sizeof(int) * (size_t)nv);
    if (!c || !fv) {
        mesh_free(c);
        free(fv);
        return errbuf_set(err, errsz, CTF_ENOMEM, "out of memory");
    }
    for (int v = 0; v < m->nv; v++)
        if (coarse[(size_t)v] >= 0) {
            fv[coarse[(size_t)v]] = v;
            std::memcpy(c->v + 3 * coarse[(size_t)v], m->v + 3 * v, 3 * sizeof(double));
        }
    int t = 0;
    for (Mesh::FaceIter f = om.faces_begin(); f != om.faces_end(); ++f) {
        if (om.status(*f).deleted())
            continue;
        int k = 0;
        for (Mesh::FaceVertexIter w = om.fv_iter(*f); w.is_valid(); ++w)
            c->f[3 * t + k++] = coarse[(size_t)w->idx()];
        t++;
    }
    *out = c;
    *fine_vertex = fv;
    return CTF_OK;
}
}  // namespace

extern "C" int ctf_decimate(const mesh *m, int target_nv, const int *keep, int nkeep,
                            mesh **out, int **fine_vertex, char *err, size_t errsz)
{
    *out = NULL;
    *fine_vertex = NULL;
    if (target_nv < 4 || target_nv > m->nv)
        return errbuf_set(err, errsz, CTF_EINPUT, "decimation to %d vertices of a mesh of %d",
                          target_nv, m->nv);
    for (int r = 0; r < nkeep; r++)
        if (keep[r] < 0 || keep[r] >= m->nv)
            return errbuf_set(err, errsz, CTF_EINPUT, "kept vertex %d out of range", keep[r]);
    try {
        return decimate(m, target_nv, keep, nkeep, out, fine_vertex, err, errsz);
    } catch (const std::bad_alloc &) {
        return errbuf_set(err, errsz, CTF_ENOMEM, "out of memory");
    } catch (...) {
        return errbuf_set(err, errsz, CTF_EFAILED, "the decimater threw an exception");
    }
}
