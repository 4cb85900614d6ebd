/* Core: result strings, the cell grid, CSV output. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

START_TEST(result_strings_name_every_code) {
    ck_assert_str_eq(fsdem_result_string(FSDEM_OK), "FSDEM_OK");
    ck_assert_str_eq(fsdem_result_string(FSDEM_ERR_OUT_OF_DOMAIN), "FSDEM_ERR_OUT_OF_DOMAIN");
    ck_assert_str_eq(fsdem_result_string((fsdem_result)-99), "FSDEM_ERR_UNKNOWN");
}
END_TEST

/* Every point lands in exactly one cell, the cells partition the items, and a point's
   neighbourhood holds every other point closer than one cell size (the property neighbour search
   relies on), checked against brute force. */
START_TEST(cellgrid_neighbourhood_covers_all_close_points) {
    fsdem_cellgrid g;
    fsdem_vec3 pts[500];
    int i, j, k, c, dim;
    for (dim = 2; dim <= 3; ++dim) {
        memset(&g, 0, sizeof g);
        srand(7);
        for (i = 0; i < 500; ++i)
            pts[i] = fsdem_v3(rand() / (fsdem_real)RAND_MAX, rand() / (fsdem_real)RAND_MAX,
                              dim == 3 ? rand() / (fsdem_real)RAND_MAX : 0);
        ck_assert_int_eq(fsdem_cellgrid_setup(&g, NULL, dim, fsdem_v3(0, 0, 0), fsdem_v3(1, 1, 1), 0.1, 0), FSDEM_OK);
        ck_assert_int_eq(fsdem_cellgrid_build(&g, pts, 500), FSDEM_OK);
        ck_assert_int_eq(g.cell_start[g.cell_count], 500);
        for (i = 0; i < 500; ++i) {
            int coord[3], cells[27], nc, found_close = 0, close = 0;
            fsdem_cellgrid_cell(&g, pts[i], coord);
            nc = fsdem_cellgrid_neighbourhood(&g, coord, cells);
            for (j = 0; j < 500; ++j) {
                fsdem_real dx = pts[i].x - pts[j].x, dy = pts[i].y - pts[j].y, dz = pts[i].z - pts[j].z;
                if (dx * dx + dy * dy + dz * dz < g.cell_size * g.cell_size) close++;
            }
            for (c = 0; c < nc; ++c)
                for (k = g.cell_start[cells[c]]; k < g.cell_start[cells[c] + 1]; ++k) {
                    int j2 = g.items[k];
                    fsdem_real dx = pts[i].x - pts[j2].x, dy = pts[i].y - pts[j2].y, dz = pts[i].z - pts[j2].z;
                    if (dx * dx + dy * dy + dz * dz < g.cell_size * g.cell_size) found_close++;
                }
            ck_assert_int_eq(found_close, close);
        }
        fsdem_cellgrid_free(&g);
    }
}
END_TEST

/* A huge box with a tiny cell size is coarsened to max_cells instead of exhausting memory. */
START_TEST(cellgrid_bounds_its_memory) {
    fsdem_cellgrid g;
    memset(&g, 0, sizeof g);
    ck_assert_int_eq(fsdem_cellgrid_setup(&g, NULL, 3, fsdem_v3(0, 0, 0), fsdem_v3(1e3, 1e3, 1e3), 1e-3, 4096),
                     FSDEM_OK);
    ck_assert_int_le(g.cell_count, 4096);
    ck_assert_int_eq(fsdem_cellgrid_setup(&g, NULL, 3, fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 1), 0.1, 0),
                     FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_cellgrid_setup(&g, NULL, 4, fsdem_v3(0, 0, 0), fsdem_v3(1, 1, 1), 0.1, 0),
                     FSDEM_ERR_INVALID_ARG);
    fsdem_cellgrid_free(&g);
}
END_TEST

START_TEST(csv_rows_match_header) {
    fsdem_csv csv;
    fsdem_real row[3] = {0, 1.5, -2};
    char line[128];
    FILE *fp;
    ck_assert_int_eq(fsdem_csv_open(&csv, "build/test_core.csv", "t,x,z"), FSDEM_OK);
    ck_assert_int_eq(fsdem_csv_row(&csv, row, 2), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_csv_row(&csv, row, 3), FSDEM_OK);
    ck_assert_int_eq(fsdem_csv_close(&csv), FSDEM_OK);
    fp = fopen("build/test_core.csv", "r");
    ck_assert_ptr_nonnull(fp);
    ck_assert_ptr_nonnull(fgets(line, sizeof line, fp));
    ck_assert_str_eq(line, "t,x,z\n");
    ck_assert_ptr_nonnull(fgets(line, sizeof line, fp));
    ck_assert_str_eq(line, "0,1.5,-2\n");
    fclose(fp);
    ck_assert_int_eq(fsdem_csv_open(&csv, "build/no/such/dir/x.csv", "t"), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_csv_open(&csv, "build/x.csv", ""), FSDEM_ERR_INVALID_ARG);
}
END_TEST

Suite *core_suite(void) {
    Suite *s = suite_create("core");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, result_strings_name_every_code);
    tcase_add_test(tc, cellgrid_neighbourhood_covers_all_close_points);
    tcase_add_test(tc, cellgrid_bounds_its_memory);
    tcase_add_test(tc, csv_rows_match_header);
    suite_add_tcase(s, tc);
    return s;
}
