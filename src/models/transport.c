/* lubkit transport properties (see transport.h). */
#include "models/transport.h"

#include "io/dict.h"

void lub_transport_read(const char *path, double *rho, double *nu)
{
    lub_dict *d = lub_dict_read(path);
    lub_node *root = lub_dict_root(d);
    *rho = lub_dict_real(root, "rho", LUB_POSITIVE);
    *nu = lub_dict_real(root, "nu", LUB_POSITIVE);
    lub_dict_finish(d);
    lub_dict_free(d);
}
