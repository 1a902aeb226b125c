/* numba_unpickle for the loops compiled ahead of time: each pickled constant unpickled once, then kept.

   A compiled loop that returns an array unpickles its dtype, and one that raises unpickles its exception,
   through numba_unpickle. numba's JIT keeps what it unpickled, keyed by the pickled bytes' address
   (numba.core.serialize._numba_unpickle); pycc's C part (numba/_helperlib.c under PYCC_COMPILING) unpickles
   them again on every call: about 7,700 instructions each, 3.4 % of a pitch bearing FMU's step.

   fmu_build/aot.py compiles this file after numba's pycc/modulemixin.c, whose numba_unpickle it renames
   numba_unpickle_each_time (see aot.memoised_mixin). The pickled bytes are constants of the module, so their
   address names them for the life of the process; the kept objects are shared as numba's JIT shares them
   (a new reference each call). Called with the GIL held. */

static PyObject *unpickled_constants;      /* {address of the pickled bytes: the object} */

NUMBA_EXPORT_FUNC(PyObject *)
numba_unpickle(const char *data, int n, const char *hashed)
{
    PyObject *key, *obj;

    if (unpickled_constants == NULL && (unpickled_constants = PyDict_New()) == NULL)
        return NULL;
    key = PyLong_FromVoidPtr((void *) data);
    if (key == NULL)
        return NULL;
    obj = PyDict_GetItemWithError(unpickled_constants, key);     /* borrowed */
    if (obj != NULL) {
        Py_INCREF(obj);
    } else if (!PyErr_Occurred()) {
        obj = numba_unpickle_each_time(data, n, hashed);
        if (obj != NULL && PyDict_SetItem(unpickled_constants, key, obj) < 0)
            Py_CLEAR(obj);
    }
    Py_DECREF(key);
    return obj;
}
