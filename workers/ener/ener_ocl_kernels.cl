/* ener_ocl_kernels.cl — the OpenCL C 1.2 kernels of ener_ocl.c: the passes of
 * ener_def_eval (ener_def.c's DESIGN comment) and of
 * ener_def_update_admissible, one work-item per element, in double
 * precision. Embedded into the library at build time (the Makefile turns it
 * into a C array); never read from disk at run time.
 *
 * ener_ocl.c builds it after a prelude that enables cl_khr_fp64 and turns
 * FP_CONTRACT off (the CPU build does not fuse either), and after
 * ener_normal.h and ener_membrane.h: the per-element arithmetic is the CPU's,
 * not a copy of it. Those helpers take private pointers, so each kernel
 * loads its element into private arrays first.
 *
 * Energies and admissible counts are reduced per work-group in local
 * memory by a fixed tree (the group size is fixed by the host), one partial
 * per group; the host adds the partials in order. No atomics: the same bits
 * on every run. */

static void ener__load3(__global const double *Y, int v, double y[3])
{
    y[0] = Y[3 * v];
    y[1] = Y[3 * v + 1];
    y[2] = Y[3 * v + 2];
}

/* Tree sum of v over the work-group into part[group]; every item calls it. */
static void ener__group_sum(__local double *buf, double v, __global double *part)
{
    const int lid = get_local_id(0);
    buf[lid] = v;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int s = get_local_size(0) / 2; s > 0; s >>= 1) {
        if (lid < s)
            buf[lid] += buf[lid + s];
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (lid == 0)
        part[get_group_id(0)] = buf[0];
}

/* Pass A: membrane energy of face t, α times its gradient into gf (9), unit
 * normal and 1/|c| into fn (4). fref: ĝ⁻¹ {a, b, c} and â per face. */
__kernel void ener_k_faces(__global const double *Y, __global const int *f,
                           __global const double *fref, const int nf,
                           const double log_eps, const double alpha, const int want_grad,
                           __global double *fn, __global double *gf,
                           __global double *part, __local double *buf)
{
    const int t = get_global_id(0);
    double e = 0.0;
    if (t < nf) {
        double y0[3], y1[3], y2[3];
        ener__load3(Y, f[3 * t], y0);
        ener__load3(Y, f[3 * t + 1], y1);
        ener__load3(Y, f[3 * t + 2], y2);
        const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
        const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1],
                             e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        double un[3];
        const double r = ener__unit_normal_of(e1, e2, n, un);
        fn[4 * t] = un[0];
        fn[4 * t + 1] = un[1];
        fn[4 * t + 2] = un[2];
        fn[4 * t + 3] = r;
        const double ginv[3] = {fref[4 * t], fref[4 * t + 1], fref[4 * t + 2]};
        const double ahat = fref[4 * t + 3];
        const double det = ener__membrane_det(ginv, n);
        double g[9];
        e = ener__membrane_finish(ginv, ahat, alpha * ahat, log_eps, e1, e2, n, det,
                                  log(det > log_eps ? det : log_eps), g);
        if (want_grad)
            for (int k = 0; k < 9; k++)
                gf[9 * t + k] = g[k];
    }
    ener__group_sum(buf, e, part);
}

/* Pass B: bending term of interior edge e from its faces' normals, and
 * η·∂term/∂⟨n_t, n_t'⟩ into ecoef. et: the two faces; ed: sign, cos θ̂,
 * l̂²/d̂. The group partials go after the faces' (from part_off). */
__kernel void ener_k_edges(__global const double *fn, __global const int *et,
                           __global const double *ed, __global const uchar *adm,
                           const int ne, const double eta, __global double *ecoef,
                           __global double *part, const int part_off, __local double *buf)
{
    const int e = get_global_id(0);
    double s = 0.0;
    if (e < ne) {
        __global const double *n1 = fn + 4 * et[2 * e];
        __global const double *n2 = fn + 4 * et[2 * e + 1];
        if (!adm[e] || n1[3] == 0.0 || n2[3] == 0.0) {
            ecoef[e] = 0.0;
        } else {
            const double sign = ed[3 * e], cos_ref = ed[3 * e + 1], weight = ed[3 * e + 2];
            const double cs = sign * (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]);
            const double diff = cos_ref - cs;
            s = weight * diff * diff;
            ecoef[e] = -2.0 * eta * weight * diff * sign;
        }
    }
    ener__group_sum(buf, s, part + part_off);
}

/* Pass C: the bending gradient of face t through its normal, added to gf. */
__kernel void ener_k_bend(__global const double *Y, __global const int *f,
                          __global const double *fn, __global const int *fedge,
                          __global const int *fnbr, __global const double *ecoef,
                          const int nf, __global double *gf)
{
    const int t = get_global_id(0);
    if (t >= nf)
        return;
    double u[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++) {
        const int e = fedge[3 * t + k];
        if (e < 0)
            continue;
        __global const double *m = fn + 4 * fnbr[3 * t + k];
        u[0] += ecoef[e] * m[0];
        u[1] += ecoef[e] * m[1];
        u[2] += ecoef[e] * m[2];
    }
    double y0[3], y1[3], y2[3], g[9];
    ener__load3(Y, f[3 * t], y0);
    ener__load3(Y, f[3 * t + 1], y1);
    ener__load3(Y, f[3 * t + 2], y2);
    const double n[3] = {fn[4 * t], fn[4 * t + 1], fn[4 * t + 2]};
    for (int k = 0; k < 9; k++)
        g[k] = gf[9 * t + k];
    ener__unit_normal_backprop(y0, y1, y2, n, fn[4 * t + 3], u, g);
    for (int k = 0; k < 9; k++)
        gf[9 * t + k] = g[k];
}

/* Pass D: vertex i's gradient, the sum of its faces' corner slots in the
 * sorted vertex -> face order of geo_edges. */
__kernel void ener_k_gather(__global const double *gf, __global const int *vf_start,
                            __global const int *vf_face, __global const int *vf_corner,
                            const int nv, __global double *grad)
{
    const int i = get_global_id(0);
    if (i >= nv)
        return;
    double gx = 0.0, gy = 0.0, gz = 0.0;
    for (int s = vf_start[i]; s < vf_start[i + 1]; s++) {
        __global const double *g = gf + 9 * vf_face[s] + 3 * vf_corner[s];
        gx += g[0];
        gy += g[1];
        gz += g[2];
    }
    grad[3 * i] = gx;
    grad[3 * i + 1] = gy;
    grad[3 * i + 2] = gz;
}

/* Admissibility, step 1: face t is non-degenerate in Y when
 * |e1 × e2|² > r2·â² (r2 = 4·ratio², ener_def_ref.h). */
__kernel void ener_k_face_ok(__global const double *Y, __global const int *f,
                             __global const double *fref, const int nf, const double r2,
                             __global uchar *fok)
{
    const int t = get_global_id(0);
    if (t >= nf)
        return;
    double y0[3], y1[3], y2[3];
    ener__load3(Y, f[3 * t], y0);
    ener__load3(Y, f[3 * t + 1], y1);
    ener__load3(Y, f[3 * t + 2], y2);
    fok[t] = (uchar)ener__face_admissible(y0, y1, y2, fref[4 * t + 3], r2);
}

/* Admissibility, step 2: edge e is admissible when both faces are; the
 * group's count (as a double, exact below 2^53) into part. */
__kernel void ener_k_edge_adm(__global const uchar *fok, __global const int *et,
                              const int ne, __global uchar *adm,
                              __global double *part, __local double *buf)
{
    const int e = get_global_id(0);
    double c = 0.0;
    if (e < ne) {
        const uchar a = fok[et[2 * e]] && fok[et[2 * e + 1]];
        adm[e] = a;
        c = a;
    }
    ener__group_sum(buf, c, part);
}
