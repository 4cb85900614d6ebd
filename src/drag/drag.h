/* ===== >>drag : drag laws of unresolved couplings (seed 002 Eq. 25-28 and the literature) ===== */

/* The drag of the fluid on one sphere of diameter d and volume V = pi d^3 / 6 at porosity eps (fluid
   volume fraction around it), for the couplers whose grid or particles are coarser than the sphere:
       F = c V (u - v),   c = beta / (1 - eps)   (kg m^-3 s^-1)
   with u the intrinsic fluid velocity at the sphere, v the sphere's, beta the interphase momentum
   exchange coefficient of seed 002 Eq. 25-26. F is the drag WITHOUT the pressure-gradient part: a
   coupler adds -V grad P itself (seed 002 Eq. 34, Model A), or uses F / eps - V rho_f g where only the
   dynamic pressure comes from the drag (Eq. 35, Model B). c is returned rather than beta because it
   stays finite at eps = 1 (a lone sphere), where beta = 0.

   Reynolds numbers: Re = eps rho_f d |u - v| / mu_f (Eq. 28, the superficial slip) for the laws of a
   suspension; Re = rho_f d |u - v| / mu_f for the isolated-sphere laws. mu_f is the DYNAMIC viscosity.
   Every law is written so that |u - v| = 0 (Re = 0) gives its creeping-flow limit, no 0/0.

   Each published form converted to c (each sense checked against Eq. 26, see >>impl_drag):
     STOKES            c = 18 mu / d^2: c V = 3 pi mu d.
     SCHILLER_NAUMANN  the isolated sphere's F = Cd (pi d^2 / 8) rho |u - v|^2 with Cd of Eq. 27
                       (Schiller and Naumann 1933; 0.44 above Re = 1000): c = 0.75 Cd rho |u - v| / d.
     ERGUN_WEN_YU      Eq. 26 as printed, divided by (1 - eps): Ergun (1952) for eps <= 0.8,
                       c = 150 (1 - eps) mu / (eps d^2) + 1.75 rho |u - v| / d; Wen and Yu (1966) above,
                       c = 0.75 Cd rho |u - v| eps^-1.65 / d (Cd of Eq. 27 at the Re of Eq. 28). c jumps
                       at eps = 0.8: d = 1 mm in water (1000 kg/m^3, 1e-3 Pa s) at 0.01 m/s (Re = 8)
                       has c = 55000 on the Ergun side and 52866.60 on the Wen-Yu side (-3.9 %).
     GIDASPOW          the two terms of Eq. 26 blended as Huilin and Gidaspow (2003),
                       beta = (1 - phi) beta_WenYu + phi beta_Ergun, phi = 1/2 + atan(262.5 (eps_s - 0.2)) / pi,
                       eps_s = 1 - eps (262.5 = 150 * 1.75): smooth, half and half at eps = 0.8. The
                       Ergun share never vanishes: 0.606 % at eps = 1, where c is 0.99394 of Stokes.
     DI_FELICE         Di Felice (1994): F = F0 eps^-chi, F0 the single-sphere drag at the superficial
                       slip U = eps |u - v| (Cd0 = (0.63 + 4.8 / sqrt(Re))^2, Re of Eq. 28),
                       chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2): c = 0.75 Cd0 rho |u - v| eps^(2 - chi) / d.
                       F is already the drag of Eq. 25 (see >>impl_drag). Its creeping limit is 0.96 of
                       Stokes (Cd0 -> 23.04 / Re). Below eps = 0.435 c falls as the slip grows over a
                       band of Re (0.29 to 1.7 at eps = 0.4, 0.024 to 5 at eps = 0.05) where chi falls
                       faster than Cd0 |u - v| grows; the force c V |u - v| still grows.
     BEETSTRA          Beetstra, van der Hoef and Kuipers (2007): F(phi, Re) = F_d / (3 pi mu d eps |u - v|),
                       phi = 1 - eps, F_d the drag of Eq. 25 (the total force is F_d / eps):
                       c = 18 mu eps F / d^2, exactly Stokes at eps = 1, Re = 0.
     GIC               seed 004 Eq. 5b, the quadratic drag of the Granule-In-Cell method:
                       F = 12 pi r^2 rho C |u - v| (u - v) with the seed's coefficient C = 0.44
                       (Schiller 1933, its §6): c = 18 C rho |u - v| / d. Porosity and viscosity do not
                       enter; there is no creeping-flow term, so c = 0 at |u - v| = 0 and a grain in
                       this law settles at |u - v| = sqrt((rho_s - rho_f) g d / (18 C rho_f)). The
                       seed's ablation with C = 0.044 (§6.1) is this law scaled by 0.1 (fsdem_gic_desc
                       drag_scale). */
typedef enum fsdem_drag_law {
    FSDEM_DRAG_LAW_STOKES = 0,           /* isolated sphere, creeping flow: 3 pi mu d, porosity ignored */
    FSDEM_DRAG_LAW_SCHILLER_NAUMANN = 1, /* isolated sphere, Cd of Eq. 27, Re = rho d |u - v| / mu, porosity ignored */
    FSDEM_DRAG_LAW_ERGUN_WEN_YU = 2,     /* seed 002 Eq. 26 exactly: Ergun for eps <= 0.8, Wen-Yu above */
    FSDEM_DRAG_LAW_GIDASPOW = 3,         /* Ergun and Wen-Yu joined by the smooth blend of Huilin and Gidaspow (2003) */
    FSDEM_DRAG_LAW_DI_FELICE = 4,        /* Di Felice (1994) */
    FSDEM_DRAG_LAW_BEETSTRA = 5,         /* Beetstra, van der Hoef and Kuipers (2007) */
    FSDEM_DRAG_LAW_GIC = 6               /* seed 004 Eq. 5b: quadratic, coefficient 0.44 */
} fsdem_drag_law;

/* Coefficient of the drag on one particle: F = c V (u - v) as above. Writes c (kg m^-3 s^-1) to
   *per_volume and beta = c (1 - eps) to *beta; either pointer may be NULL. porosity in (0, 1],
   diameter > 0 (m), slip_speed = |u - v| in [0, FSDEM_MAX_SPEED] (m/s), density rho_f > 0 (kg/m^3),
   viscosity mu_f > 0 (dynamic, Pa s), all finite, and a known law; otherwise FSDEM_ERR_INVALID_ARG,
   nothing written, and `message` (may be NULL) names the argument. Every law is finite for any
   Reynolds number; FSDEM_ERR_NAN (nothing written, the message gives porosity, d and Re) only where
   c itself exceeds the largest fsdem_real (a vanishing diameter or porosity). */
FSDEM_API fsdem_result fsdem_drag_coefficient(fsdem_drag_law law, fsdem_real porosity, fsdem_real diameter,
                                              fsdem_real slip_speed, fsdem_real density, fsdem_real viscosity,
                                              fsdem_real *per_volume, fsdem_real *beta, char *message,
                                              size_t message_size);

/* Name of a law ("ergun_wen_yu", ...), "unknown" for other values. Never NULL. */
FSDEM_API const char *fsdem_drag_law_name(fsdem_drag_law law);
