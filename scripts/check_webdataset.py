"""Streams a data set's WebDataset tars with the `webdataset` package (a loader nobody here
wrote) and holds every sample to the same set written as a folder: the same files under
each key, byte for byte. Prints the number of samples.

    python3 check_webdataset.py TARS_DIR FOLDER_DIR
"""
import glob
import os
import sys

import webdataset as wds

tars, folder = sys.argv[1], sys.argv[2]
urls = sorted(glob.glob(os.path.join(tars, "set-*.tar")))
if not urls:
    sys.exit(f"{tars}: no set-*.tar")
count = 0
for sample in wds.WebDataset(urls, shardshuffle=False):
    key = sample["__key__"]
    got = sorted(f"{key}.{ext}" for ext in sample if not ext.startswith("__"))
    wanted = sorted(n for n in os.listdir(folder) if n.startswith(key + ".") and ".tmp" not in n)
    if got != wanted:
        sys.exit(f"{key}: the tar holds {got}, the folder {wanted}")
    for name in got:
        with open(os.path.join(folder, name), "rb") as f:
            if f.read() != sample[name[len(key) + 1:]]:
                sys.exit(f"{name}: the tar's bytes differ from the folder's")
    count += 1
print(f"{count} samples")
