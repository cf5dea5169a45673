/* Strain, law and loads of one deformable element (see element.h and docs/elements.md).
 *
 * Every load here is derived from the virtual work of the law's force on the exact variation of
 * the strain, so forces and moments balance exactly, and a potential-based strain (rod, linear
 * spring, POTENTIAL angular part) gives a conservative field. The invariant forms are written so
 * that trading the two ends changes every intermediate quantity by an exact sign flip (or not at
 * all): swapping the bodies then gives the same loads to the last bit, not just to round-off. */
#include "element/element.h"

int ws_element_type_dim(ws_element_type type)
{
    switch (type) {
    case WS_ELEMENT_ROD:
        return 1;
    case WS_ELEMENT_LINEAR_SPRING:
    case WS_ELEMENT_ANGULAR_SPRING:
        return 3;
    case WS_ELEMENT_BUSHING:
        return 6;
    }
    return 0;
}

static int has_linear(ws_element_type t)
{
    return t == WS_ELEMENT_LINEAR_SPRING || t == WS_ELEMENT_BUSHING;
}
static int has_angular(ws_element_type t)
{
    return t == WS_ELEMENT_ANGULAR_SPRING || t == WS_ELEMENT_BUSHING;
}

void ws_element_kinematics(const ws_element *e, const ws_element_end end[2], ws_element_kin *k)
{
    v3 vp[2];
    for (int i = 0; i < 2; i++) {
        m3 A = qt_to_m3(end[i].p);
        k->arm[i] = m3_mul_v(&A, e->point[i]);
        k->pt[i] = v3_add(end[i].x, k->arm[i]);
        vp[i] = v3_add(end[i].v, v3_cross(end[i].w, k->arm[i])); /* eq. 3 */
    }
    k->l = v3_sub(k->pt[1], k->pt[0]);
    v3 ldot = v3_sub(vp[1], vp[0]);
    for (int i = 0; i < 6; i++)
        k->u[i] = k->ud[i] = 0.0;
    k->theta = k->tau = k->dir = v3_make(0, 0, 0);
    k->q = qt_identity();
    k->E = m3_identity();

    if (e->type == WS_ELEMENT_ROD) {
        /* eps = |l|/l0 - 1 (the slide's square root is a misprint: eps must be linear in the
         * stretch for a spring of stiffness k/l0). */
        double len = v3_norm(k->l);
        if (len > 0.0)
            k->dir = v3_scale(k->l, 1.0 / len);
        k->u[0] = len / e->l0 - 1.0;
        k->ud[0] = v3_dot(k->dir, ldot) / e->l0;
        return;
    }

    qt a = qt_mul(end[0].p, e->frame[0]), b = qt_mul(end[1].p, e->frame[1]);
    v3 wE; /* angular velocity of the law frame, global */
    if (e->form == WS_ELEMENT_ATTACHED) {
        k->q = a;
        k->theta = qt_to_rotvec(qt_relative(a, b));
        wE = end[0].w;
    } else {
        /* b and -b are one rotation: take the one nearer to a, so that the relative rotation is
         * the principal one (|theta| <= pi) and a + b is the mid rotation. The test a . b < 0 is
         * the same number whichever end is first. */
        if (a.e0 * b.e0 + a.e1 * b.e1 + a.e2 * b.e2 + a.e3 * b.e3 < 0.0) {
            b.e0 = -b.e0;
            b.e1 = -b.e1;
            b.e2 = -b.e2;
            b.e3 = -b.e3;
        }
        k->theta = qt_to_rotvec(qt_relative(a, b));
        /* The geodesic midpoint of two unit quaternions is their normalised sum: it equals
         * a (x) exp(theta/2) and is symmetric in a and b to the last bit (a sign flip of the
         * sum, when b was negated, does not change the rotation matrix). */
        qt m = {a.e0 + b.e0, a.e1 + b.e1, a.e2 + b.e2, a.e3 + b.e3};
        k->q = qt_normalize(m);
    }
    k->E = qt_to_m3(k->q);
    if (e->form != WS_ELEMENT_ATTACHED) {
        double ang = v3_norm(k->theta);
        double c = ang > 1e-8 ? tan(0.25 * ang) / ang : 0.25; /* tan(a/4)/a -> 1/4 */
        k->tau = v3_scale(m3_mul_v(&k->E, k->theta), c);
        /* The mid frame's angular velocity, from (I + G) w_m = w_2 + G w_1, G the rotation
         * from frame 1 to the mid frame (docs/elements.md). */
        v3 w1 = end[0].w, w2 = end[1].w;
        wE = v3_add(v3_scale(v3_add(w1, w2), 0.5), v3_scale(v3_cross(k->tau, v3_sub(w1, w2)), 0.5));
    }

    int off = 0;
    if (has_linear(e->type)) {
        /* d = E^T l; its exact rate E^T (l_dot - w_E x l), the frame turning with w_E. */
        v3 d = m3_tmul_v(&k->E, k->l);
        v3 dd = m3_tmul_v(&k->E, v3_sub(ldot, v3_cross(wE, k->l)));
        v3_store(k->u, d);
        v3_store(k->ud, dd);
        off = 3;
    }
    if (has_angular(e->type)) {
        /* The seed's relative angular velocity in the law frame; theta_dot = H(theta) times it
         * for the potential form, where the law's F is work-conjugate to theta. */
        v3 wr = m3_tmul_v(&k->E, v3_sub(end[1].w, end[0].w));
        if (e->form == WS_ELEMENT_POTENTIAL)
            wr = rotvec_mid_map(k->theta, wr);
        v3_store(k->u + off, k->theta);
        v3_store(k->ud + off, wr);
    }
}

void ws_element_loads_of(const ws_element *e, const ws_element_kin *k, const double *F,
                         ws_element_loads *out)
{
    const double sgn[2] = {1.0, -1.0};
    v3 f = v3_make(0, 0, 0), M = v3_make(0, 0, 0), extra[2] = {{0, 0, 0}, {0, 0, 0}};
    if (e->type == WS_ELEMENT_ROD) {
        /* U(|l|) with dU/d|l| = F: body 1 is pulled towards body 2 by the tension. */
        f = v3_scale(k->dir, F[0]);
    } else {
        int off = 0;
        if (has_linear(e->type)) {
            /* delta d = E^T (delta l - delta phi_E x l): the force E F at each point, and the
             * frame's turning adds the moment c = l x f on whatever carries the frame: body 1
             * (attached), or the mid frame's share of each body (invariant). */
            f = m3_mul_v(&k->E, v3_load(F));
            v3 c = v3_cross(k->l, f);
            if (e->form == WS_ELEMENT_ATTACHED) {
                extra[0] = c;
            } else {
                v3 half = v3_scale(c, 0.5), twist = v3_scale(v3_cross(c, k->tau), 0.5);
                extra[0] = v3_add(half, twist);
                extra[1] = v3_sub(half, twist);
            }
            off = 3;
        }
        if (has_angular(e->type)) {
            /* The seed: M1 = +E Mbar, M2 = -E Mbar, Mbar = F (attached, invariant), or
             * Mbar = H(theta) F, the exact derivative of the energy (potential). */
            v3 Mbar = v3_load(F + off);
            if (e->form == WS_ELEMENT_POTENTIAL)
                Mbar = rotvec_mid_map(k->theta, Mbar);
            M = m3_mul_v(&k->E, Mbar);
        }
    }
    for (int i = 0; i < 2; i++) {
        /* The same expression for both ends, the roles entering only through exact signs. */
        v3 fi = v3_scale(f, sgn[i]);
        out->f[i] = fi;
        out->mp[i] = v3_add(extra[i], v3_scale(M, sgn[i]));
        out->m[i] = v3_add(v3_cross(k->arm[i], fi), out->mp[i]);
    }
}

int ws_element_eval(const ws_element *e, const ws_law *L, const ws_element_end end[2], double t,
                    ws_element_kin *k, double *F, ws_element_loads *out)
{
    ws_element_kinematics(e, end, k);
    double dt = t - e->t_commit;
    if (!(dt >= 0.0))
        dt = 0.0; /* the world's time never runs back; guard against round-off only */
    int rc = ws_law_eval(L, e->state, k->u, k->ud, t, dt, F, NULL, NULL);
    if (rc != 0)
        return rc;
    ws_element_loads_of(e, k, F, out);
    return 0;
}

double ws_element_energy(const ws_element *e, const ws_law *L, const ws_element_kin *k, double t)
{
    double u = ws_law_elastic_energy_at(L, e->state, k->u, t);
    /* A 1D law's energy is per unit rest length (its strain is dimensionless). */
    return e->type == WS_ELEMENT_ROD ? u * e->l0 : u;
}
