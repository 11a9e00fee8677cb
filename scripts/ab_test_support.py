"""What ab_run_test.py and ab_sweep_test.py share: a stand-in pitchlab written as a script."""
import os
import stat


def write_executable(folder, name, text):
    """Writes `text` to folder/name, executable by its owner; returns the path."""
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path
