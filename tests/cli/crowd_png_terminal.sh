# bench/crowd refuses to write its picture (--png) or plot (--plot) to a
# terminal, as the tools refuse binary output to one: exit 1 with a
# message, before measuring (a new-user probe saw `--png /dev/tty` write
# PNG bytes to the terminal and exit 0). The terminal is a pseudo-terminal
# opened here; its name is shown as TTY.
set -u
"$BIN/mlod-pack" -o t.mlod "$ROOT/samples/tubeman.glb" || exit 99
python3 - "$BIN/../bench/crowd" <<'PY'
import os, pty, subprocess, sys, threading
m, s = pty.openpty()
name = os.ttyname(s)
def drain():
    try:
        while os.read(m, 65536):
            pass
    except OSError:
        pass
threading.Thread(target=drain, daemon=True).start()
rc = 0
for opt in ('--png', '--plot'):
    r = subprocess.run([sys.argv[1], '-n', '1', '-s', '0.1', '--no-skin-bench', '--png-size', '16x16', opt, name,
                        't.mlod'], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=120)
    sys.stderr.write(r.stderr.decode().replace(name, 'TTY'))
    rc = rc or r.returncode
sys.exit(rc)
PY
