/* lubkit transport properties: constant/transportProperties.yaml.
 *
 *     rho: 850        # density [kg/m^3], > 0
 *     nu:  2.25e-4    # kinematic viscosity [m^2/s], > 0
 *
 * Both are required; any other key is an error (strict, file:line:col).
 */
#ifndef LUB_MODELS_TRANSPORT_H
#define LUB_MODELS_TRANSPORT_H

/* Read the file at path (fatal with file:line on bad input, or when it is missing). */
void lub_transport_read(const char *path, double *rho, double *nu);

#endif
