/* Drag laws (>>drag; seed 002 Eq. 25-28): each law against values worked out by hand from its
   paper's formula, the creeping and dilute limits, the switch of Eq. 26 at eps = 0.8, monotony in the
   slip, bad input and the names. */
#include "fsdem_tests.h"
#include <string.h>

#define TEST_PI 3.14159265358979323846

/* c (kg m^-3 s^-1) of `law`, asserting success. */
static double test_c(fsdem_drag_law law, double eps, double d, double slip, double rho, double mu) {
    fsdem_real c = -1;
    char msg[256] = "";
    const fsdem_result r = fsdem_drag_coefficient(law, (fsdem_real)eps, (fsdem_real)d, (fsdem_real)slip, (fsdem_real)rho,
                                                  (fsdem_real)mu, &c, NULL, msg, sizeof msg);
    ck_assert_msg(r == FSDEM_OK, "%s eps %g d %g slip %g: %s (%s)", fsdem_drag_law_name(law), eps, d, slip,
                  fsdem_result_string(r), msg);
    return (double)c;
}

/* c V / (3 pi mu d): the drag of the law over that of Stokes. */
static double test_over_stokes(fsdem_drag_law law, double eps, double d, double slip, double rho, double mu) {
    return test_c(law, eps, d, slip, rho, mu) * (TEST_PI * d * d * d / 6) / (3 * TEST_PI * mu * d);
}

START_TEST(test_drag_by_hand) {
    /* Worked out by hand (python3 with mpmath at 30 digits) from each paper's formula as published,
       then c = F / (V slip) or c = beta / (1 - eps); water (1000 kg/m^3, 1e-3 Pa s) or air (1.2, 1.8e-5).
         STOKES            F = 3 pi mu d slip
         SCHILLER_NAUMANN  Re = rho d slip / mu, Cd = 24 / Re (1 + 0.15 Re^0.687) (0.44 above Re 1000),
                           F = Cd (pi d^2 / 4) rho slip^2 / 2
         ERGUN_WEN_YU      seed 002 Eq. 26-28: beta = 150 (1 - eps)^2 mu / (eps d^2) + 1.75 (1 - eps) rho slip / d
                           for eps <= 0.8, else 0.75 Cd eps (1 - eps) rho slip eps^-2.65 / d, Cd of Eq. 27 at
                           Re = eps rho d slip / mu
         GIDASPOW          beta = (1 - phi) beta_WenYu + phi beta_Ergun, phi = 1/2 + atan(262.5 (1 - eps - 0.2)) / pi
         DI_FELICE         Re = eps rho d slip / mu, Cd0 = (0.63 + 4.8 / sqrt(Re))^2,
                           chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2), F = Cd0 (pi d^2 / 4) rho (eps slip)^2 / 2 eps^-chi
         BEETSTRA          phi = 1 - eps, Re = eps rho d slip / mu, F = 10 phi / eps^2 + eps^2 (1 + 1.5 sqrt(phi))
                           + 0.413 Re / (24 eps^2) (1 / eps + 3 phi eps + 8.4 Re^-0.343) / (1 + 10^(3 phi) Re^(-(1 + 4 phi) / 2)),
                           F_d = 3 pi mu d eps slip F */
    static const struct {
        fsdem_drag_law law;
        double eps, d, slip, rho, mu, c;
    } pt[] = {
        {FSDEM_DRAG_LAW_STOKES, 0.5, 1e-3, 0.01, 1000, 1e-3, 18000.0},                    /* Re 10 */
        {FSDEM_DRAG_LAW_STOKES, 1, 2e-3, 0, 1000, 1e-3, 4500.0},                          /* Re 0 */
        {FSDEM_DRAG_LAW_STOKES, 0.3, 5e-4, 1, 1.2, 1.8e-5, 1296.0},                       /* Re 33, air */
        {FSDEM_DRAG_LAW_SCHILLER_NAUMANN, 0.5, 1e-3, 1e-4, 1000, 1e-3, 18555.09046091572}, /* Re 0.1 */
        {FSDEM_DRAG_LAW_SCHILLER_NAUMANN, 0.7, 1e-3, 0.01, 1000, 1e-3, 31132.99455366946}, /* Re 10 */
        {FSDEM_DRAG_LAW_SCHILLER_NAUMANN, 1, 1e-3, 0.5, 1000, 1e-3, 210999.4881109174},    /* Re 500 */
        {FSDEM_DRAG_LAW_SCHILLER_NAUMANN, 0.9, 1e-3, 2, 1000, 1e-3, 660000.0},             /* Re 2000, Cd 0.44 */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.4, 1e-3, 0.01, 1000, 1e-3, 242500.0},              /* Ergun, Re 4 */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.6, 1e-3, 0.5, 1000, 1e-3, 975000.0},               /* Ergun, Re 300 */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.8, 1e-3, 0.01, 1000, 1e-3, 55000.0},               /* Ergun at the switch, Re 8 */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.5, 2e-4, 0.3, 1.2, 1.8e-5, 70650.0},               /* Ergun, Re 2, air */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.95, 1e-3, 1e-4, 1000, 1e-3, 21234.66595818474},    /* Wen-Yu, Re 0.095 */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.9, 1e-3, 0.5, 1000, 1e-3, 261141.3389686217},      /* Wen-Yu, Re 450 */
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.99, 1e-3, 1.2, 1000, 1e-3, 402621.6412201916},     /* Wen-Yu, Re 1188, Cd 0.44 */
        {FSDEM_DRAG_LAW_GIDASPOW, 0.4, 1e-3, 0.01, 1000, 1e-3, 242624.0801949256},         /* Re 4 */
        {FSDEM_DRAG_LAW_GIDASPOW, 0.7, 1e-3, 0.1, 1000, 1e-3, 238506.2806930664},          /* Re 70 */
        {FSDEM_DRAG_LAW_GIDASPOW, 0.8, 1e-3, 0.01, 1000, 1e-3, 53933.30025266872},         /* Re 8, phi = 1/2 */
        {FSDEM_DRAG_LAW_GIDASPOW, 0.9, 1e-3, 0.5, 1000, 1e-3, 268783.4509735878},          /* Re 450 */
        {FSDEM_DRAG_LAW_DI_FELICE, 0.4, 1e-3, 1e-4, 1000, 1e-3, 214094.5240637036},        /* Re 0.04 */
        {FSDEM_DRAG_LAW_DI_FELICE, 0.75, 2e-4, 0.3, 1.2, 1.8e-5, 22797.3826430913},        /* Re 3, air */
        {FSDEM_DRAG_LAW_DI_FELICE, 0.6, 1e-3, 0.05, 1000, 1e-3, 145500.835272926},         /* Re 30 */
        {FSDEM_DRAG_LAW_DI_FELICE, 0.9, 1e-3, 0.5, 1000, 1e-3, 317503.2710881037},         /* Re 450 */
        {FSDEM_DRAG_LAW_BEETSTRA, 0.4, 1e-3, 1e-4, 1000, 1e-3, 272490.5619576339},         /* Re 0.04 */
        {FSDEM_DRAG_LAW_BEETSTRA, 0.75, 2e-4, 0.3, 1.2, 1.8e-5, 34465.57587356321},        /* Re 3, air */
        {FSDEM_DRAG_LAW_BEETSTRA, 0.6, 1e-3, 0.05, 1000, 1e-3, 192660.1646375388},         /* Re 30 */
        {FSDEM_DRAG_LAW_BEETSTRA, 0.9, 1e-3, 0.5, 1000, 1e-3, 403193.7123828798},          /* Re 450 */
        /* seed 004 Eq. 5b: c = 18 (0.44) rho slip / d whatever eps and mu */
        {FSDEM_DRAG_LAW_GIC, 0.5, 1e-3, 0.05, 1000, 1e-3, 396000.0},
        {FSDEM_DRAG_LAW_GIC, 1, 7.8e-4, 0.01, 1000, 1e-2, 101538.4615384615},
        {FSDEM_DRAG_LAW_GIC, 0.7, 1e-3, 0, 1000, 1e-3, 0.0},                              /* no creeping term */
    };
    /* rounding of the inputs to fsdem_real and of a few pow/exp calls, relative */
    const double tol = TOL(1e-12, 64);
    size_t i;
    for (i = 0; i < sizeof pt / sizeof pt[0]; ++i) {
        fsdem_real c = -1, beta = -1;
        ck_assert_int_eq(fsdem_drag_coefficient(pt[i].law, (fsdem_real)pt[i].eps, (fsdem_real)pt[i].d, (fsdem_real)pt[i].slip,
                                                (fsdem_real)pt[i].rho, (fsdem_real)pt[i].mu, &c, &beta, NULL, 0),
                         FSDEM_OK);
        ck_assert_msg(fabs(c - pt[i].c) <= tol * pt[i].c, "%s eps %g slip %g: c %.16g, by hand %.16g (rel %.3g)",
                      fsdem_drag_law_name(pt[i].law), pt[i].eps, pt[i].slip, (double)c, pt[i].c, fabs(c - pt[i].c) / pt[i].c);
        ck_assert_msg(fabs(beta - c * (1 - (fsdem_real)pt[i].eps)) <= 4 * TEST_EPS * c, "beta %g is not c (1 - eps)", (double)beta);
    }
}
END_TEST

START_TEST(test_drag_switch_at_0_8) {
    /* Eq. 26 switches at eps = 0.8 with a jump; Gidaspow's blend does not. d = 1 mm in water at 0.01 m/s.
       Just above 0.8: 0.8 + 1e-9 in double, one float step (0.8 + 1e-7) in float, where Wen-Yu changes by
       3e-7 relative, within the float tolerance. */
    const double above = TEST_FLOAT ? 0.8000001 : 0.800000001, below = TEST_FLOAT ? 0.7999999 : 0.799999999;
    const double ergun = test_c(FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.8, 1e-3, 0.01, 1000, 1e-3);
    const double wen_yu = test_c(FSDEM_DRAG_LAW_ERGUN_WEN_YU, above, 1e-3, 0.01, 1000, 1e-3);
    const double g_below = test_c(FSDEM_DRAG_LAW_GIDASPOW, below, 1e-3, 0.01, 1000, 1e-3);
    const double g_above = test_c(FSDEM_DRAG_LAW_GIDASPOW, above, 1e-3, 0.01, 1000, 1e-3);
    const double g_jump = fabs(g_above - g_below) / g_below, step = (double)(fsdem_real)above - (double)(fsdem_real)below;
    ck_assert((fsdem_real)above > (fsdem_real)0.8 && (fsdem_real)below < (fsdem_real)0.8);
    /* by hand: Ergun 150 * 0.2 / 0.8 * 1e-3 / 1e-6 + 1.75 * 1000 * 0.01 / 1e-3 = 37500 + 17500; Wen-Yu at
       Re = 8: 0.75 * 24 / 8 (1 + 0.15 * 8^0.687) * 1000 * 0.01 * (0.8 + 1e-9)^-1.65 / 1e-3 */
    ck_assert_msg(fabs(ergun - 55000) <= TOL(1e-12, 64) * 55000, "Ergun side %.16g", ergun);
    ck_assert_msg(fabs(wen_yu - 52866.60034769374) <= TOL(1e-12, 64) * 52866.6, "Wen-Yu side %.16g", wen_yu);
    /* smooth: c changes like its slope there, d ln c / d eps = 6.9 (the blend's 262.5 / pi times the jump of 2133
       over 53933, plus the terms' own slopes), times the step (2e-9 in double, 3 float steps in float) */
    ck_assert_msg(g_jump < 10 * step, "Gidaspow moves by %.3g across 0.8 (step %.3g)", g_jump, step);
    TEST_REPORT("Eq. 26 at eps = 0.8: c = %.10g (Ergun) -> %.10g (Wen-Yu), jump %.4f %%; Gidaspow %.10g -> %.10g (rel %.3g)",
                ergun, wen_yu, 100 * (wen_yu - ergun) / ergun, g_below, g_above, g_jump);
}
END_TEST

START_TEST(test_drag_limits) {
    /* eps = 1 and Re = 0: Stokes' 3 pi mu d for the laws that reduce to it. */
    static const fsdem_drag_law exact[] = {FSDEM_DRAG_LAW_STOKES, FSDEM_DRAG_LAW_SCHILLER_NAUMANN, FSDEM_DRAG_LAW_ERGUN_WEN_YU,
                                           FSDEM_DRAG_LAW_BEETSTRA};
    static const fsdem_drag_law all[] = {FSDEM_DRAG_LAW_STOKES, FSDEM_DRAG_LAW_SCHILLER_NAUMANN, FSDEM_DRAG_LAW_ERGUN_WEN_YU,
                                         FSDEM_DRAG_LAW_GIDASPOW, FSDEM_DRAG_LAW_DI_FELICE, FSDEM_DRAG_LAW_BEETSTRA};
    /* the Ergun share of the blend at eps = 1 is 1/2 - atan(52.5) / pi = 0.606 %, and Ergun's c vanishes at eps = 1,
       Re = 0; Di Felice: 0.75 * 4.8^2 / 18 = 0.96 */
    const double gidaspow = test_over_stokes(FSDEM_DRAG_LAW_GIDASPOW, 1, 1e-3, 0, 1000, 1e-3);
    const double di_felice = test_over_stokes(FSDEM_DRAG_LAW_DI_FELICE, 1, 1e-3, 0, 1000, 1e-3);
    size_t i;
    for (i = 0; i < sizeof exact / sizeof exact[0]; ++i) {
        const double r = test_over_stokes(exact[i], 1, 2e-3, 0, 1000, 1e-3);
        ck_assert_msg(fabs(r - 1) <= TOL(1e-14, 16), "%s: %.17g of Stokes at eps 1, Re 0", fsdem_drag_law_name(exact[i]), r);
    }
    ck_assert_msg(fabs(gidaspow - 0.99393768763743) <= TOL(1e-12, 64), "Gidaspow %.15g of Stokes", gidaspow);
    ck_assert_msg(fabs(di_felice - 0.96) <= TOL(1e-12, 64), "Di Felice %.15g of Stokes", di_felice);
    /* the Re -> 0 and eps -> 1 limits written out in the code are the limits of the formulas: at Re = 1e-6 every law
       is within 1e-3 of its slip = 0 value (Di Felice's 0.63 sqrt(Re) term moves it most, 2.6e-4), and at
       eps = 1 - 1e-6 within 1 % of eps = 1 (Beetstra's 1.5 sqrt(phi) moves it most, 1.5e-3) */
    for (i = 0; i < sizeof all / sizeof all[0]; ++i) {
        const double c0 = test_c(all[i], 1, 1e-3, 0, 1000, 1e-3);
        const double near_re = test_c(all[i], 1, 1e-3, 1e-9, 1000, 1e-3), near_eps = test_c(all[i], 1 - 1e-6, 1e-3, 0, 1000, 1e-3);
        ck_assert_msg(fabs(near_re / c0 - 1) < 1e-3, "%s: Re 1e-6 gives %.10g, Re 0 %.10g", fsdem_drag_law_name(all[i]), near_re, c0);
        ck_assert_msg(fabs(near_eps / c0 - 1) < 1e-2, "%s: eps 1 - 1e-6 gives %.10g, eps 1 %.10g", fsdem_drag_law_name(all[i]),
                      near_eps, c0);
    }
    TEST_REPORT("eps 1, Re 0 over Stokes: Gidaspow %.12f, Di Felice %.12f", gidaspow, di_felice);
}
END_TEST

START_TEST(test_drag_monotone_in_slip) {
    static const double eps[] = {0.05, 0.4, 0.6, 0.8, 0.85, 0.95, 1};
    int law, e, k;
    for (law = FSDEM_DRAG_LAW_STOKES; law <= FSDEM_DRAG_LAW_BEETSTRA; ++law)
        for (e = 0; e < (int)(sizeof eps / sizeof eps[0]); ++e) {
            double prev = test_c((fsdem_drag_law)law, eps[e], 1e-3, 0, 1000, 1e-3);
            ck_assert_msg(prev > 0 && isfinite(prev), "%s eps %g: c %g at slip 0", fsdem_drag_law_name((fsdem_drag_law)law),
                          eps[e], prev);
            /* Di Felice's c dips below eps ~ 0.435 (checked below) */
            if (law == FSDEM_DRAG_LAW_DI_FELICE && eps[e] < 0.5) continue;
            /* slip 1e-7 to 10 m/s, Re up to 1e4, 8 per decade */
            for (k = 0; k <= 64; ++k) {
                const double slip = 1e-7 * pow(10, k / 8.0), c = test_c((fsdem_drag_law)law, eps[e], 1e-3, slip, 1000, 1e-3);
                ck_assert_msg(c >= prev * (1 - 8 * TEST_EPS), "%s eps %g: c %.12g at slip %g after %.12g",
                              fsdem_drag_law_name((fsdem_drag_law)law), eps[e], c, slip, prev);
                prev = c;
            }
        }
    /* Di Felice at eps = 0.4: chi falls from 3.7 towards 3.05 as Re grows to 31.6, and eps^-chi with it, faster
       than Cd0 slip grows: c (by hand) 218007.8985604854 at Re = 0.2, 215680.0852306065 at Re = 2; the force
       c V slip still grows tenfold */
    {
        const double c1 = test_c(FSDEM_DRAG_LAW_DI_FELICE, 0.4, 1e-3, 5e-4, 1000, 1e-3);
        const double c2 = test_c(FSDEM_DRAG_LAW_DI_FELICE, 0.4, 1e-3, 5e-3, 1000, 1e-3);
        ck_assert_msg(fabs(c1 - 218007.8985604854) <= TOL(1e-12, 64) * c1 && fabs(c2 - 215680.0852306065) <= TOL(1e-12, 64) * c2,
                      "Di Felice at eps 0.4: %.16g, %.16g", c1, c2);
        TEST_REPORT("Di Felice, eps 0.4: c %.10g at Re 0.2, %.10g at Re 2", c1, c2);
    }
}
END_TEST

START_TEST(test_drag_bad_input) {
    static const struct {
        int law;
        double eps, d, slip, rho, mu;
        const char *names;
    } bad[] = {
        {99, 0.5, 1e-3, 0.01, 1000, 1e-3, "law"},
        {-1, 0.5, 1e-3, 0.01, 1000, 1e-3, "law"},
        {FSDEM_DRAG_LAW_STOKES, 0, 1e-3, 0.01, 1000, 1e-3, "porosity"},
        {FSDEM_DRAG_LAW_GIDASPOW, 1.5, 1e-3, 0.01, 1000, 1e-3, "porosity"},
        {FSDEM_DRAG_LAW_BEETSTRA, NAN, 1e-3, 0.01, 1000, 1e-3, "porosity"},
        {FSDEM_DRAG_LAW_DI_FELICE, 0.5, 0, 0.01, 1000, 1e-3, "diameter"},
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.5, -1e-3, 0.01, 1000, 1e-3, "diameter"},
        {FSDEM_DRAG_LAW_ERGUN_WEN_YU, 0.5, INFINITY, 0.01, 1000, 1e-3, "diameter"},
        {FSDEM_DRAG_LAW_SCHILLER_NAUMANN, 0.5, 1e-3, -0.01, 1000, 1e-3, "slip_speed"},
        {FSDEM_DRAG_LAW_SCHILLER_NAUMANN, 0.5, 1e-3, NAN, 1000, 1e-3, "slip_speed"},
        {FSDEM_DRAG_LAW_DI_FELICE, 0.5, 1e-3, 0.01, 0, 1e-3, "density"},
        {FSDEM_DRAG_LAW_BEETSTRA, 0.5, 1e-3, 0.01, 1000, 0, "viscosity"},
        {FSDEM_DRAG_LAW_BEETSTRA, 0.5, 1e-3, 0.01, 1000, INFINITY, "viscosity"},
    };
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        fsdem_real c = -7, beta = -7;
        char msg[256] = "";
        const fsdem_result r = fsdem_drag_coefficient((fsdem_drag_law)bad[i].law, (fsdem_real)bad[i].eps, (fsdem_real)bad[i].d,
                                                      (fsdem_real)bad[i].slip, (fsdem_real)bad[i].rho, (fsdem_real)bad[i].mu,
                                                      &c, &beta, msg, sizeof msg);
        ck_assert_msg(r == FSDEM_ERR_INVALID_ARG, "case %d: %s", (int)i, fsdem_result_string(r));
        ck_assert_msg(strstr(msg, "fsdem_drag_coefficient: ") == msg && strstr(msg, bad[i].names), "case %d: '%s'", (int)i, msg);
        ck_assert(c == -7 && beta == -7);
        ck_assert_int_eq(fsdem_drag_coefficient((fsdem_drag_law)bad[i].law, (fsdem_real)bad[i].eps, (fsdem_real)bad[i].d,
                                                (fsdem_real)bad[i].slip, (fsdem_real)bad[i].rho, (fsdem_real)bad[i].mu, NULL,
                                                NULL, NULL, 0),
                         FSDEM_ERR_INVALID_ARG);
    }
    {
        /* valid but so small a sphere that 18 mu / d^2 overflows */
        fsdem_real c = -7, beta = -7;
        char msg[256] = "";
        ck_assert_int_eq(fsdem_drag_coefficient(FSDEM_DRAG_LAW_STOKES, 0.5, (fsdem_real)(TEST_FLOAT ? 1e-30 : 1e-200), 0, 1000,
                                                (fsdem_real)1e-3, &c, &beta, msg, sizeof msg),
                         FSDEM_ERR_NAN);
        ck_assert(c == -7 && beta == -7 && strstr(msg, "overflows"));
    }
    /* NULL outputs are allowed; beta is 0 at eps = 1 where c is finite */
    {
        fsdem_real beta = -7;
        ck_assert_int_eq(fsdem_drag_coefficient(FSDEM_DRAG_LAW_GIDASPOW, 1, (fsdem_real)1e-3, 0, 1000, (fsdem_real)1e-3, NULL, &beta,
                                                NULL, 0),
                         FSDEM_OK);
        ck_assert(beta == 0);
    }
}
END_TEST

START_TEST(test_drag_names) {
    static const char *const expected[] = {"stokes", "schiller_naumann", "ergun_wen_yu", "gidaspow", "di_felice", "beetstra"};
    int law, other;
    for (law = FSDEM_DRAG_LAW_STOKES; law <= FSDEM_DRAG_LAW_BEETSTRA; ++law) {
        ck_assert_str_eq(fsdem_drag_law_name((fsdem_drag_law)law), expected[law]);
        for (other = 0; other < law; ++other)
            ck_assert_str_ne(fsdem_drag_law_name((fsdem_drag_law)law), fsdem_drag_law_name((fsdem_drag_law)other));
    }
    ck_assert_str_eq(fsdem_drag_law_name((fsdem_drag_law)99), "unknown");
    ck_assert_str_eq(fsdem_drag_law_name((fsdem_drag_law)-1), "unknown");
}
END_TEST

Suite *drag_suite(void) {
    Suite *s = suite_create("drag");
    TCase *tc = tcase_create("drag");
    tcase_add_test(tc, test_drag_by_hand);
    tcase_add_test(tc, test_drag_switch_at_0_8);
    tcase_add_test(tc, test_drag_limits);
    tcase_add_test(tc, test_drag_monotone_in_slip);
    tcase_add_test(tc, test_drag_bad_input);
    tcase_add_test(tc, test_drag_names);
    suite_add_tcase(s, tc);
    return s;
}
