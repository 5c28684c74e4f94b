/* A program built against an installed libblend, as a user would build it. */
#include <libblend/libblend.h>

#include <stdio.h>

int main(void) {
    const double x[2] = {0.1, 0.2}, r[2] = {0.5, 0.5}, p[2] = {2, 2};
    double v;
    lb_error e;
    if (lb_displacement(LB_UNION, 2, x, r, p, NULL, &v, NULL, &e) != LB_OK) {
        fprintf(stderr, "%s\n", e.message);
        return 1;
    }
    /* a union blend of two arguments lies below their minimum */
    if (!(v < 0.1)) return 1;
    printf("%d %.17g\n", lb_version(), v);
    return 0;
}
