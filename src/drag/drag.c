/* ===== >>impl_drag : drag laws ===== */

/* Contents: the Wen-Yu term (also the Schiller-Naumann law, at eps = 1), the per-law coefficient
   c = beta / (1 - eps) without checks for the couplers' per-particle loops, the checked public function
   and the names.

   Why each published form is read as the drag of seed 002 Eq. 25 (the -V grad P part excluded):
   - Ergun: the beta of Eq. 26 with -eps grad P in the fluid's momentum balance gives Ergun's pressure
     drop, 150 phi^2 mu U / (eps^3 d^2) at the superficial U.
   - Di Felice: in a settling suspension the drag in this sense balances the weight less the buoyancy
     of the suspension's density, eps (rho_p - rho_f) g V; with Richardson-Zaki's n = 4.65 that makes
     chi = n - 1 = 3.65, Di Felice's 3.7, and his form with chi = 3.65 and Cd of Eq. 27 is exactly the
     Wen-Yu branch of Eq. 26 (eps^(2 - 3.65) = eps^-1.65). (Read as the total force, F / eps, chi would
     have to be n = 4.65.)
   - Beetstra: F(phi, 0) = 10 phi / eps^2 + ... gives c = 180 phi mu / (eps d^2), the Carman-Kozeny
     twin of Ergun's 150 phi mu / (eps d^2) in Eq. 26; read as the total force it would be eps times
     that, off from Ergun by a factor eps. */

/* Wen and Yu (1966) as in seed 002 Eq. 26: c = 0.75 Cd rho slip eps^-1.65 / d with Cd of Eq. 27 at
   Re = eps rho d slip / mu (Eq. 28). Written with Cd Re = 24 (1 + 0.15 Re^0.687) and rho slip / d =
   Re mu / (eps d^2), so Re = 0 gives 18 mu eps^-2.65 / d^2 with no 0/0. At eps = 1 this is the
   Schiller-Naumann law of an isolated sphere. */
static fsdem_real fsdem__drag_wen_yu(fsdem_real eps, fsdem_real d, fsdem_real slip, fsdem_real rho, fsdem_real mu) {
    const fsdem_real re = eps * rho * d * slip / mu;
    const fsdem_real cd_re = re <= 1000 ? 24 * (1 + (fsdem_real)0.15 * (fsdem_real)pow(re, 0.687)) : (fsdem_real)0.44 * re;
    return (fsdem_real)0.75 * cd_re * mu / (d * d) * (fsdem_real)pow(eps, -2.65);
}

/* Ergun (1952) as in seed 002 Eq. 26, divided by (1 - eps). */
static fsdem_real fsdem__drag_ergun(fsdem_real eps, fsdem_real d, fsdem_real slip, fsdem_real rho, fsdem_real mu) {
    return 150 * (1 - eps) * mu / (eps * d * d) + (fsdem_real)1.75 * rho * slip / d;
}

/* The coefficient mu of seed 004 Eq. 5b, as its §6 gives it. */
#define FSDEM__GIC_DRAG_COEFFICIENT ((fsdem_real)0.44)

/* c of `law` (kg m^-3 s^-1) for valid arguments (fsdem_drag_coefficient checks them). */
static fsdem_real fsdem__drag_per_volume(fsdem_drag_law law, fsdem_real eps, fsdem_real d, fsdem_real slip,
                                         fsdem_real rho, fsdem_real mu) {
    switch (law) {
    case FSDEM_DRAG_LAW_STOKES: return 18 * mu / (d * d);
    case FSDEM_DRAG_LAW_SCHILLER_NAUMANN: return fsdem__drag_wen_yu(1, d, slip, rho, mu);
    case FSDEM_DRAG_LAW_ERGUN_WEN_YU:
        /* the switch in fsdem_real, so a float build puts eps = 0.8f on the Ergun side too */
        return eps <= (fsdem_real)0.8 ? fsdem__drag_ergun(eps, d, slip, rho, mu) : fsdem__drag_wen_yu(eps, d, slip, rho, mu);
    case FSDEM_DRAG_LAW_GIDASPOW: {
        /* the blend of beta is the same blend of c: both terms carry the one factor (1 - eps) */
        const fsdem_real phi = (fsdem_real)(0.5 + atan(262.5 * ((1 - eps) - 0.2)) / FSDEM__PI);
        return (1 - phi) * fsdem__drag_wen_yu(eps, d, slip, rho, mu) + phi * fsdem__drag_ergun(eps, d, slip, rho, mu);
    }
    case FSDEM_DRAG_LAW_DI_FELICE: {
        /* Cd0 slip = (0.63 sqrt(slip) + 4.8 sqrt(slip / Re))^2 with slip / Re = mu / (eps rho d): finite at
           Re = 0, where chi -> 3.7 (the Gaussian in log10 Re vanishes) and c -> 17.28 mu eps^-2.7 / d^2 */
        const fsdem_real re = eps * rho * d * slip / mu;
        const fsdem_real lg = re > 0 ? (fsdem_real)1.5 - (fsdem_real)log10(re) : 0;
        const fsdem_real chi = re > 0 ? (fsdem_real)(3.7 - 0.65 * exp(-0.5 * lg * lg)) : (fsdem_real)3.7;
        const fsdem_real root = (fsdem_real)(0.63 * sqrt(slip) + 4.8 * sqrt(mu / (eps * rho * d)));
        return (fsdem_real)0.75 * rho * root * root * (fsdem_real)pow(eps, 2 - chi) / d;
    }
    case FSDEM_DRAG_LAW_BEETSTRA: {
        /* the Re term Re / (24 eps^2) (A + 8.4 Re^-0.343) / (1 + 10^(3 phi) Re^-a), a = (1 + 4 phi) / 2,
           written (Re A + 8.4 Re^0.657) / (24 eps^2 (1 + 10^(3 phi) Re^-a)): Re^-a overflows to
           infinity as Re -> 0, where the term is 0, and vanishes as Re grows, where it tends to
           (Re A + 8.4 Re^0.657) / (24 eps^2); multiplied through by Re^a instead, both Re^a and its
           denominator overflow for large Re and give inf / inf */
        const fsdem_real phi = 1 - eps, re = eps * rho * d * slip / mu;
        const fsdem_real inertial =
            re > 0 ? (re * (1 / eps + 3 * phi * eps) + (fsdem_real)8.4 * (fsdem_real)pow(re, 0.657)) /
                         (24 * eps * eps * (1 + (fsdem_real)pow(10.0, 3 * phi) * (fsdem_real)pow(re, -(0.5 + 2 * phi))))
                   : 0;
        const fsdem_real f = 10 * phi / (eps * eps) + eps * eps * (1 + (fsdem_real)1.5 * (fsdem_real)sqrt(phi)) +
                             (fsdem_real)0.413 * inertial;
        return 18 * mu * eps * f / (d * d);
    }
    case FSDEM_DRAG_LAW_GIC: return 18 * FSDEM__GIC_DRAG_COEFFICIENT * rho * slip / d; /* seed 004 Eq. 5b */
    }
    return 0;
}

const char *fsdem_drag_law_name(fsdem_drag_law law) {
    switch (law) {
    case FSDEM_DRAG_LAW_STOKES: return "stokes";
    case FSDEM_DRAG_LAW_SCHILLER_NAUMANN: return "schiller_naumann";
    case FSDEM_DRAG_LAW_ERGUN_WEN_YU: return "ergun_wen_yu";
    case FSDEM_DRAG_LAW_GIDASPOW: return "gidaspow";
    case FSDEM_DRAG_LAW_DI_FELICE: return "di_felice";
    case FSDEM_DRAG_LAW_BEETSTRA: return "beetstra";
    case FSDEM_DRAG_LAW_GIC: return "gic";
    }
    return "unknown";
}

fsdem_result fsdem_drag_coefficient(fsdem_drag_law law, fsdem_real porosity, fsdem_real diameter, fsdem_real slip_speed,
                                    fsdem_real density, fsdem_real viscosity, fsdem_real *per_volume, fsdem_real *beta,
                                    char *message, size_t message_size) {
    static const char fn[] = "fsdem_drag_coefficient";
    fsdem_real c;
    if ((int)law < (int)FSDEM_DRAG_LAW_STOKES || (int)law > (int)FSDEM_DRAG_LAW_GIC)
        return fsdem__reject(message, message_size, "%s: law must be a fsdem_drag_law, got %d", fn, (int)law);
    if (!(porosity > 0 && porosity <= 1))
        return fsdem__reject(message, message_size, "%s: porosity must be in (0, 1], got %g", fn, (double)porosity);
    if (!(diameter > 0) || !fsdem__finite(diameter))
        return fsdem__reject(message, message_size, "%s: diameter must be > 0 and finite, got %g m", fn, (double)diameter);
    if (!(slip_speed >= 0 && slip_speed <= FSDEM_MAX_SPEED))
        return fsdem__reject(message, message_size, "%s: slip_speed must be in [0, FSDEM_MAX_SPEED = %g] m/s, got %g m/s", fn,
                             (double)FSDEM_MAX_SPEED, (double)slip_speed);
    if (!(density > 0) || !fsdem__finite(density))
        return fsdem__reject(message, message_size, "%s: density must be > 0 and finite, got %g kg/m^3", fn, (double)density);
    if (!(viscosity > 0) || !fsdem__finite(viscosity))
        return fsdem__reject(message, message_size, "%s: viscosity must be > 0 and finite, got %g Pa s", fn,
                             (double)viscosity);
    c = fsdem__drag_per_volume(law, porosity, diameter, slip_speed, density, viscosity);
    if (!fsdem__finite(c)) {
        if (message && message_size)
            snprintf(message, message_size, "%s: c = %g kg m^-3 s^-1 overflows for porosity %g, d = %g m, Re = %g", fn, (double)c,
                     (double)porosity, (double)diameter, (double)(porosity * density * diameter * slip_speed / viscosity));
        return FSDEM_ERR_NAN;
    }
    if (per_volume) *per_volume = c;
    if (beta) *beta = c * (1 - porosity);
    return FSDEM_OK;
}
