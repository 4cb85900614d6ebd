/* Runs every suite; the exit status is the number of failures (0 on success). */
#include <stdlib.h>
#include "fsdem_tests.h"

int main(void) {
    SRunner *runner = srunner_create(core_suite());
    int failed;
    srunner_add_suite(runner, dem_suite());
    srunner_add_suite(runner, linalg_suite());
    srunner_add_suite(runner, pic_suite());
    srunner_add_suite(runner, swe_suite());
    srunner_add_suite(runner, couple_swe_suite());
    srunner_add_suite(runner, interface_suite());
    srunner_add_suite(runner, restart_suite());
    srunner_add_suite(runner, robustness_suite());
    srunner_add_suite(runner, io_suite());
    srunner_add_suite(runner, mps_suite());
    srunner_add_suite(runner, drag_suite());
    srunner_add_suite(runner, couple_mps_suite());
    srunner_add_suite(runner, couple_pic_suite());
    srunner_add_suite(runner, couple_gic_suite());
    srunner_add_suite(runner, couple_suite());
    srunner_add_suite(runner, probing_suite());
    srunner_add_suite(runner, dem_contact_suite());
    srunner_add_suite(runner, dem_periodic_suite());
    srunner_add_suite(runner, mps_periodic_suite());
    srunner_run_all(runner, CK_NORMAL);
    failed = srunner_ntests_failed(runner);
    srunner_free(runner);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
