"""Usage: png_software.py VERSION_LINE FILE...: each PNG carries VERSION_LINE as its Software text
(an uncompressed iTXt chunk, as core/analysis/heatmap's writer stores it); exit 1 naming the first
file that does not."""
import sys

version = sys.argv[1].encode()
for path in sys.argv[2:]:
    if b"iTXtSoftware\0\0\0\0\0" + version not in open(path, "rb").read():
        print(f"FAIL: {path}: no Software text naming {sys.argv[1]}")
        sys.exit(1)
