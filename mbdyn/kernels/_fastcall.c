/* The hottest per-call methods (Model.mass_matrix, Model.effort_array,
 * Model.forward_dynamics by articulated bodies) at the cost of one C call:
 * mbdyn/kernels/fastcall.py says what, why and when.
 *
 * An Entry holds the model's two packed buffers and the C address of a compiled kernel
 * (numba cfunc of fastcall.py).  Called with the method's arrays, it checks each is
 * exactly a numpy array, float64 in native byte order, 1-d of the model's size,
 * C-contiguous and aligned; takes a result array (a recycled one nothing else refers to,
 * else a new one); calls the kernel; and returns the result, or None for anything else (an
 * argument of another kind or size, a kernel status other than success): the caller then
 * takes its checked route, which converts, computes again and says what is wrong.  The
 * entry never raises for a bad argument and never writes into an array the caller holds.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <stddef.h>
#include <stdint.h>

/* the kernels' C signatures (fastcall.MASS_MATRIX, fastcall.EFFORTS, fastcall.FORWARD) */
typedef int64_t (*mass_matrix_fn)(double *fb, int64_t nfb, int64_t *ib, int64_t nib,
                                  double *q, int64_t nq, double *M, int64_t nu);
typedef int64_t (*efforts_fn)(double *fb, int64_t nfb, int64_t *ib, int64_t nib,
                              int64_t forces, double *q, int64_t nq, double *u,
                              double *u_dot, int64_t nu, double *tau);
typedef int64_t (*forward_fn)(double *fb, int64_t nfb, int64_t *ib, int64_t nib,
                              int64_t forces, double *q, int64_t nq, double *u, int64_t nu,
                              double *u_rate);

enum { MASS_MATRIX = 0, EFFORTS = 1, FORWARD = 2 };
static const Py_ssize_t ARGUMENTS[] = {1, 3, 2};   /* (q), (q, u, u_dot), (q, u) */

typedef struct {
    PyObject_HEAD
    vectorcallfunc vectorcall;
    void *kernel;
    int kind;
    PyArrayObject *fb, *ib;     /* the model's buffers, held for the entry's life */
    int64_t forces;             /* the address of the force elements' function */
    npy_intp nq, nu;
    int recycle;
    PyArrayObject *spare[2];    /* results returned before, taken back once let go of */
} Entry;

/* Whether a is an array the kernel may read as n contiguous float64 values. */
static int plain(PyObject *a, npy_intp n)
{
    if (Py_TYPE(a) != &PyArray_Type)
        return 0;
    PyArrayObject *x = (PyArrayObject *)a;
    return PyArray_NDIM(x) == 1 && PyArray_DIM(x, 0) == n
        && PyArray_DESCR(x)->type_num == NPY_DOUBLE && PyArray_ISNOTSWAPPED(x)
        && PyArray_IS_C_CONTIGUOUS(x) && PyArray_ISALIGNED(x);
}

/* Whether the spare s is free (only the entry refers to it) and still as it was made:
 * float64, writable, C-contiguous, of the result's shape, owning its data. */
static int free_spare(Entry *self, PyArrayObject *s, int nd)
{
    return s != NULL && Py_REFCNT(s) == 1 && PyArray_ISCARRAY(s)
        && PyArray_DESCR(s)->type_num == NPY_DOUBLE && PyArray_ISNOTSWAPPED(s)
        && PyArray_NDIM(s) == nd && PyArray_DIM(s, 0) == self->nu
        && (nd == 1 || PyArray_DIM(s, 1) == self->nu) && PyArray_BASE(s) == NULL;
}

/* A new reference to the array the result is written into. */
static PyArrayObject *result(Entry *self)
{
    int nd = self->kind == MASS_MATRIX ? 2 : 1;
    npy_intp dims[2] = {self->nu, self->nu};
    if (self->recycle) {
        for (int k = 0; k < 2; k++) {
            if (free_spare(self, self->spare[k], nd)) {
                Py_INCREF(self->spare[k]);
                return self->spare[k];
            }
        }
    }
    PyArrayObject *made = (PyArrayObject *)PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
    if (made != NULL && self->recycle) {    /* the second spare moves to the first place */
        PyArrayObject *old = self->spare[0];
        self->spare[0] = self->spare[1];
        Py_INCREF(made);
        self->spare[1] = made;
        Py_XDECREF(old);    /* last: its release may run Python code that calls us again */
    }
    return made;
}

static PyObject *Entry_call(Entry *self, PyObject *const *args, size_t nargsf,
                            PyObject *kwnames)
{
    Py_ssize_t n = PyVectorcall_NARGS(nargsf);
    if (kwnames != NULL || n != ARGUMENTS[self->kind] || !plain(args[0], self->nq))
        Py_RETURN_NONE;
    for (Py_ssize_t k = 1; k < n; k++) {
        if (!plain(args[k], self->nu))
            Py_RETURN_NONE;
    }
    PyArrayObject *out = result(self);
    if (out == NULL)
        return NULL;
    double *fb = (double *)PyArray_DATA(self->fb);
    int64_t *ib = (int64_t *)PyArray_DATA(self->ib);
    int64_t nfb = PyArray_DIM(self->fb, 0), nib = PyArray_DIM(self->ib, 0), status;
    double *q = (double *)PyArray_DATA((PyArrayObject *)args[0]);
    if (self->kind == MASS_MATRIX) {
        status = ((mass_matrix_fn)self->kernel)(fb, nfb, ib, nib, q, self->nq,
                                                (double *)PyArray_DATA(out), self->nu);
    } else if (self->kind == EFFORTS) {
        status = ((efforts_fn)self->kernel)(fb, nfb, ib, nib, self->forces, q, self->nq,
                                            (double *)PyArray_DATA((PyArrayObject *)args[1]),
                                            (double *)PyArray_DATA((PyArrayObject *)args[2]),
                                            self->nu, (double *)PyArray_DATA(out));
    } else {
        status = ((forward_fn)self->kernel)(fb, nfb, ib, nib, self->forces, q, self->nq,
                                            (double *)PyArray_DATA((PyArrayObject *)args[1]),
                                            self->nu, (double *)PyArray_DATA(out));
    }
    if (status != -1) {         /* a failure (or an exception the cfunc reported): the caller's
                                   checked route computes again and says what went wrong */
        Py_DECREF(out);
        PyErr_Clear();
        Py_RETURN_NONE;
    }
    return (PyObject *)out;
}

static PyObject *Entry_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    unsigned long long kernel;
    long long forces, nq, nu;
    int kind, recycle;
    PyArrayObject *fb, *ib;
    if (kw != NULL && PyDict_GET_SIZE(kw) != 0) {
        PyErr_SetString(PyExc_TypeError, "Entry takes positional arguments only");
        return NULL;
    }
    if (!PyArg_ParseTuple(args, "KiO!O!LLLp:Entry", &kernel, &kind, &PyArray_Type, &fb,
                          &PyArray_Type, &ib, &forces, &nq, &nu, &recycle))
        return NULL;
    if (kernel == 0 || kind < MASS_MATRIX || kind > FORWARD || nq < 0 || nu < 0
            || !PyArray_ISCARRAY(fb) || PyArray_NDIM(fb) != 1
            || PyArray_DESCR(fb)->type_num != NPY_DOUBLE || !PyArray_ISNOTSWAPPED(fb)
            || !PyArray_ISCARRAY(ib) || PyArray_NDIM(ib) != 1
            || PyArray_DESCR(ib)->type_num != NPY_INT64 || !PyArray_ISNOTSWAPPED(ib)) {
        PyErr_SetString(PyExc_ValueError,
                        "Entry(kernel address, kind 0, 1 or 2, float64 buffer, int64 buffer, "
                        "force address, nq, nu, recycle): the buffers 1-d, C-contiguous, "
                        "writable and in native byte order");
        return NULL;
    }
    Entry *self = (Entry *)type->tp_alloc(type, 0);
    if (self == NULL)
        return NULL;
    self->vectorcall = (vectorcallfunc)Entry_call;
    self->kernel = (void *)(uintptr_t)kernel;
    self->kind = kind;
    Py_INCREF(fb);
    self->fb = fb;
    Py_INCREF(ib);
    self->ib = ib;
    self->forces = forces;
    self->nq = nq;
    self->nu = nu;
    self->recycle = recycle;
    self->spare[0] = self->spare[1] = NULL;
    return (PyObject *)self;
}

static void Entry_dealloc(Entry *self)
{
    Py_XDECREF(self->fb);
    Py_XDECREF(self->ib);
    Py_XDECREF(self->spare[0]);
    Py_XDECREF(self->spare[1]);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyTypeObject EntryType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "mbdyn.kernels._fastcall.Entry",
    .tp_doc = "Entry(kernel, kind, fb, ib, forces, nq, nu, recycle): a compiled kernel "
              "called with its arrays checked in C; returns the result, or None where the "
              "caller takes its checked route (mbdyn.kernels.fastcall).",
    .tp_basicsize = sizeof(Entry),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_VECTORCALL,
    .tp_new = Entry_new,
    .tp_dealloc = (destructor)Entry_dealloc,
    .tp_call = PyVectorcall_Call,
    .tp_vectorcall_offset = offsetof(Entry, vectorcall),
};

static struct PyModuleDef fastcall_module = {
    PyModuleDef_HEAD_INIT, "_fastcall",
    "The hottest per-call methods at the cost of one C call (mbdyn.kernels.fastcall).",
    -1, NULL,
};

PyMODINIT_FUNC PyInit__fastcall(void)
{
    import_array();
    if (PyType_Ready(&EntryType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&fastcall_module);
    if (m == NULL)
        return NULL;
    Py_INCREF(&EntryType);
    if (PyModule_AddObject(m, "Entry", (PyObject *)&EntryType) < 0) {
        Py_DECREF(&EntryType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
