"""The shipped Python examples run and write what they promise."""
import os
import subprocess
import sys


def test_smile_sheet_example(root, tmp_path):
    out = tmp_path / "sheet.png"
    r = subprocess.run([sys.executable, root / "python/examples/smile_sheet.py", out, "--size", "64",
                        "--steps", "3", "--threads", "2"],
                       capture_output=True, text=True, env=os.environ.copy())
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert r.stdout.count("smile ") == 3 and "wrote" in r.stdout
