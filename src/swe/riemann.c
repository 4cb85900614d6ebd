/* ---- >>swe_riemann : face fluxes ---- */

/* Fluxes through one face along its normal. Inputs are the reconstructed states of the lower (L) and
   upper (R) sides: surface eta, depth h, normal velocity un, tangential velocity ut. */
typedef struct fsdem__swe_flux {
    fsdem_real mass;   /* m^2/s, along the normal */
    fsdem_real tan;    /* m^3/s^2, flux of tangential momentum */
    fsdem_real aL, aR; /* m^3/s^2, normal-momentum flux seen from each side minus g h*_s^2 / 2 */
    fsdem_real hL, hR; /* m, h* after the non-negative reconstruction */
    fsdem_real eL, eR; /* m, eta* */
} fsdem__swe_flux;

static inline void fsdem__swe_riemann(fsdem_real g, fsdem_real tiny, fsdem_real eL, fsdem_real hL, fsdem_real uL,
                                      fsdem_real vL, fsdem_real eR, fsdem_real hR, fsdem_real uR, fsdem_real vR,
                                      fsdem__swe_flux *f) {
    fsdem_real zL = eL - hL, zR = eR - hR;
    fsdem_real zf = zL > zR ? zL : zR, m = eL < eR ? eL : eR;
    fsdem_real hsL, hsR, cL, cR, qL, qR, sL, sR, advL, advR, pL, pR;
    if (zf <= m) {
        hsL = eL - zf;
        hsR = eR - zf;
        f->eL = eL;
        f->eR = eR;
    } else {
        /* the lower surface is below the face bed: lower the face bed to it (Liang's dz) */
        hsL = eL > zf ? eL - zf : 0;
        hsR = eR > zf ? eR - zf : 0;
        f->eL = hsL + m;
        f->eR = hsR + m;
    }
    f->hL = hsL;
    f->hR = hsR;
    /* depths below `tiny` (1e-9 dry_depth) carry no flux: they would only feed ever thinner films
       ahead of a front, whose squares end in slow subnormal arithmetic */
    if (hsL < tiny) hsL = 0;
    if (hsR < tiny) hsR = 0;
    if (!(hsL > 0) && !(hsR > 0)) {
        f->mass = f->tan = f->aL = f->aR = 0;
        return;
    }
    cL = (fsdem_real)sqrt(g * hsL);
    cR = (fsdem_real)sqrt(g * hsR);
    qL = hsL * uL;
    qR = hsR * uR;
    if (!(hsR > 0) || !(hsL > 0)) {
        /* one side dry: the exact Godunov flux of the rarefaction into dry bed (Toro 2001, ch. 5):
           for a dry right side the fan spans uL - cL .. uL + 2cL with u + 2c = uL + 2cL, so at x/t = 0
           u = c = (uL + 2cL)/3 (mirror image for a dry left side) */
        fsdem_real h0, u0, v0, a0;
        if (!(hsR > 0)) {
            a0 = uL + 2 * cL;
            if (uL - cL >= 0) { h0 = hsL; u0 = uL; }
            else if (a0 <= 0) { h0 = 0; u0 = 0; }
            else { u0 = a0 / 3; h0 = u0 * u0 / g; }
            v0 = vL;
        } else {
            a0 = uR - 2 * cR;
            if (uR + cR <= 0) { h0 = hsR; u0 = uR; }
            else if (a0 >= 0) { h0 = 0; u0 = 0; }
            else { u0 = a0 / 3; h0 = u0 * u0 / g; }
            v0 = vR;
        }
        f->mass = h0 * u0;
        f->tan = h0 * u0 * v0;
        a0 = h0 * u0 * u0 + (fsdem_real)0.5 * g * h0 * h0;
        f->aL = a0 - (fsdem_real)0.5 * g * hsL * hsL;
        f->aR = a0 - (fsdem_real)0.5 * g * hsR * hsR;
        return;
    } else {
        fsdem_real us = (fsdem_real)0.5 * (uL + uR) + cL - cR;
        fsdem_real cs = (fsdem_real)0.5 * (cL + cR) + (fsdem_real)0.25 * (uL - uR);
        if (cs < 0) cs = 0;
        sL = uL - cL < us - cs ? uL - cL : us - cs;
        sR = uR + cR > us + cs ? uR + cR : us + cs;
    }
    advL = qL * uL;
    advR = qR * uR;
    pL = (fsdem_real)0.5 * g * hsL * hsL;
    pR = (fsdem_real)0.5 * g * hsR * hsR;
    if (sL >= 0) {
        f->mass = qL;
        f->tan = qL * vL;
        f->aL = advL;
        f->aR = advL + pL - pR;
    } else if (sR <= 0) {
        f->mass = qR;
        f->tan = qR * vR;
        f->aR = advR;
        f->aL = advR + pR - pL;
    } else {
        fsdem_real inv = 1 / (sR - sL), dU = qR - qL, dF = (advR + pR) - (advL + pL);
        f->mass = (sR * qL - sL * qR + sL * sR * (hsR - hsL)) * inv;
        f->tan = (sR * qL * vL - sL * qR * vR + sL * sR * (hsR * vR - hsL * vL)) * inv;
        f->aL = advL + sL * (sR * dU - dF) * inv;
        f->aR = advR + sR * (sL * dU - dF) * inv;
    }
}

/* Boundary depth of an inflow of unit discharge q >= 0 whose outgoing Riemann invariant is R:
   solves 2 sqrt(g h) - q/h = R (increasing in h) by safeguarded Newton on s = sqrt(h). */
static fsdem_real fsdem__swe_inflow_depth(fsdem_real g, fsdem_real q, fsdem_real R) {
    double sg = sqrt((double)g), lo = 0, hi = 1e-3, s, f, df;
    int it;
    if (q <= 0) return R > 0 ? (fsdem_real)(R * R / (4 * g)) : 0;
    while (2 * sg * hi - q / (hi * hi) - R < 0 && hi < 1e6) hi *= 2;
    s = hi;
    for (it = 0; it < 100; ++it) {
        double next;
        f = 2 * sg * s - q / (s * s) - R;
        if (f < 0) lo = s;
        else hi = s;
        df = 2 * sg + 2 * q / (s * s * s);
        next = s - f / df;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (fabs(next - s) <= 1e-15 * s) {
            s = next;
            break;
        }
        s = next;
    }
    return (fsdem_real)(s * s);
}

/* Flux through a reflecting face (a WALL side or the face of a blocked cell) seen from the interior
   state e, h, un (normal velocity), ut; `upper` is 1 when the wall is on the upper side (the
   interior is then the L side): the Riemann problem against the mirror state, with no mass or
   tangential flux. */
static void fsdem__swe_wall_flux(const fsdem_swe *s, int upper, fsdem_real e, fsdem_real h, fsdem_real un, fsdem_real ut,
                                 fsdem__swe_flux *f) {
    if (upper) fsdem__swe_riemann(s->g, s->tiny, e, h, un, ut, e, h, -un, ut, f);
    else fsdem__swe_riemann(s->g, s->tiny, e, h, -un, ut, e, h, un, ut, f);
    f->mass = f->tan = 0;
}

/* Flux through a boundary face. `in_*` is the interior state; `upper` is 1 when the boundary is at the
   upper end of the axis (the interior is then the L side). Returns the fluxes in f, with the interior
   side's aL/aR, hL/hR, eL/eR filled. */
static void fsdem__swe_boundary_flux(const fsdem_swe *s, int side, int upper, fsdem_real ein, fsdem_real hin,
                                     fsdem_real unin, fsdem_real utin, fsdem__swe_flux *f) {
    const fsdem__swe_bnd *b = &s->bnd[side];
    fsdem_real value = s->bvalue[side], g = s->g, sgn = upper ? 1 : -1;
    fsdem_real zin = ein - hin, eex = ein, hex = hin, unex = unin, utex = utin;
    switch (b->type) {
    case FSDEM_SWE_BC_WALL: fsdem__swe_wall_flux(s, upper, ein, hin, unin, utin, f); return;
    case FSDEM_SWE_BC_TRANSMISSIVE: break;
    case FSDEM_SWE_BC_STAGE: {
        /* outgoing invariant w + 2c (w = outward normal velocity) carried from the interior */
        fsdem_real cin = (fsdem_real)sqrt(g * hin), cex, w;
        hex = value > zin ? value - zin : 0;
        cex = (fsdem_real)sqrt(g * hex);
        w = sgn * unin + 2 * (cin - cex);
        unex = hex > 0 ? sgn * w : 0;
        eex = zin + hex;
        break;
    }
    case FSDEM_SWE_BC_DISCHARGE: {
        fsdem_real R = sgn * unin + 2 * (fsdem_real)sqrt(g * hin);
        fsdem_real hb = fsdem__swe_inflow_depth(g, value, R);
        fsdem_real fn = hb > 0 ? value * value / hb + (fsdem_real)0.5 * g * hb * hb : 0;
        fsdem_real own = (fsdem_real)0.5 * g * hin * hin;
        f->mass = -sgn * value;
        f->tan = 0;
        f->hL = f->hR = hin;
        f->eL = f->eR = ein;
        f->aL = f->aR = fn - own;
        return;
    }
    }
    if (upper) fsdem__swe_riemann(g, s->tiny, ein, hin, unin, utin, eex, hex, unex, utex, f);
    else fsdem__swe_riemann(g, s->tiny, eex, hex, unex, utex, ein, hin, unin, utin, f);
}
