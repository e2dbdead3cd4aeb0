"""What the Python test scripts share: the skip code, the failure type and the outcome of a run in
a temporary folder (PASS, or FAIL with the reason)."""
import shutil
import tempfile
import traceback
from pathlib import Path

SKIP = 77  # ctest's SKIP_RETURN_CODE for these scripts (never under CI=true)


class Failure(Exception):
    pass


def run_in_temp_dir(prefix, run, args):
    """Runs run(args, tmp) in a fresh temporary folder, removed afterwards; the exit code."""
    tmp = Path(tempfile.mkdtemp(prefix=prefix))
    try:
        run(args, tmp)
    except Failure as e:
        print(f"FAIL: {e}")
        return 1
    except Exception:
        traceback.print_exc()
        print("FAIL: unexpected error")
        return 1
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("PASS")
    return 0
