/* fmusim's CVode solver left out of the Debian 11 build of fmusim (tests/linux_floor/build.sh): fmusim v0.0.39
 * needs sundials 6, Debian 11 has 5. The solver serves model exchange only; the tests run co-simulation
 * (--interface-type cs), which never calls it. Asked for it anyway, fmusim reports that no solver was made. */
#include <stdio.h>
#include "FMICVode.h"

FMISolver* FMICVodeCreate(const FMISolverParameters* solverFunctions)
{
    (void)solverFunctions;
    fprintf(stderr, "this fmusim is built without CVode (Debian 11's sundials is too old): use --solver euler\n");
    return NULL;
}

void FMICVodeFree(FMISolver* solver) { (void)solver; }

FMISolverStatus FMICVodeStep(FMISolver* solver, double nextTime, double* timeReached, bool* stateEvent)
{
    (void)solver; (void)nextTime; (void)timeReached; (void)stateEvent;
    return FMISolverError;
}

FMISolverStatus FMICVodeReset(FMISolver* solver, double time)
{
    (void)solver; (void)time;
    return FMISolverError;
}
