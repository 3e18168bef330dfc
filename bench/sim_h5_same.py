#!/usr/bin/python3
"""Whether two `hearth sim collect` files hold the same data, whatever
their bytes: the same groups, datasets and attributes (h5py), every
dataset with the same dtype, shape, chunk shape and filter, and the same
decoded values. For writer changes that move file bytes but must not move
what a reader gets (e.g. main's file against a branch's, same seed).

usage: sim_h5_same.py A.hdf5 B.hdf5    (exit 1 at the first difference)
"""
import sys

import h5py
import numpy as np


def fail(msg):
    print("sim_h5_same: " + msg, file=sys.stderr)
    sys.exit(1)


def same_attrs(x, y, name):
    if sorted(x.attrs) != sorted(y.attrs):
        fail("%s: attributes %r against %r" % (name or "/", sorted(x.attrs), sorted(y.attrs)))
    for k in x.attrs:
        va, vb = x.attrs[k], y.attrs[k]
        if type(va) is not type(vb) or not np.array_equal(np.asarray(va), np.asarray(vb)):
            fail("%s@%s differs" % (name or "/", k))


def walk(x, y, name, count):
    same_attrs(x, y, name)
    if isinstance(x, h5py.Dataset):
        if not isinstance(y, h5py.Dataset):
            fail("%s: a dataset in one file only" % name)
        for what in ("dtype", "shape", "chunks", "compression", "compression_opts"):
            if getattr(x, what) != getattr(y, what):
                fail("%s: %s %r against %r" % (name, what, getattr(x, what), getattr(y, what)))
        if not np.array_equal(x[()], y[()]):
            fail("%s: values differ" % name)
        count[0] += 1
        return
    if sorted(x.keys()) != sorted(y.keys()):
        fail("%s: members differ" % (name or "/"))
    for k in x:
        walk(x[k], y[k], name + "/" + k, count)


def main():
    if len(sys.argv) != 3:
        fail("usage: sim_h5_same.py A.hdf5 B.hdf5")
    count = [0]
    with h5py.File(sys.argv[1], "r") as a, h5py.File(sys.argv[2], "r") as b:
        walk(a, b, "", count)
    print("%d datasets: same dtype, shape, chunks, filter and values; same attributes" % count[0])


main()
