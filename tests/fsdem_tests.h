/* Shared declarations of the Check suite: one suite per module, and small helpers. */
#ifndef FSDEM_TESTS_H
#define FSDEM_TESTS_H
#include <check.h>
#include "fsdem.h"

Suite *core_suite(void);
Suite *dem_suite(void);
Suite *linalg_suite(void);
Suite *pic_suite(void);
Suite *swe_suite(void);
Suite *couple_swe_suite(void);
Suite *restart_suite(void);
Suite *robustness_suite(void);
Suite *io_suite(void);

#endif
