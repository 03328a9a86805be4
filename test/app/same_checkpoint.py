"""Exits 0 if two checkpoints hold the same datasets and attributes, value for value.

The attributes scene and scene_path name each run's own directory and are left out. Used by
restart.sh and retry.sh: python3 same_checkpoint.py A.h5 B.h5
"""
import sys

import h5py
import numpy as np

a, b = (h5py.File(p, "r") for p in sys.argv[1:3])


def items(f):
    out = {}
    f.visititems(lambda name, obj: out.__setitem__(name, obj[...]) if isinstance(obj, h5py.Dataset) else None)
    return out


def attributes(f):
    return {k: v for k, v in f.attrs.items() if k not in ("scene", "scene_path")}


da, db = items(a), items(b)
same = da.keys() == db.keys() and all(np.array_equal(da[k], db[k]) for k in da)
aa, ab = attributes(a), attributes(b)
same = same and aa.keys() == ab.keys() and all(np.array_equal(aa[k], ab[k]) for k in aa)
print(f"checkpoint {sys.argv[1].split('/')[-1]}: {len(da)} datasets and {len(aa)} attributes " + ("equal" if same else "DIFFER"))
sys.exit(0 if same else 1)
