#!/usr/bin/env python3
"""Bounded load test of `robocal serve --public` on loopback (issue 17 s5).

Many slow clients (slowloris: a byte of a request line every second, each
reconnecting when cut off), clients sending oversized heads (32 KiB of
header) and stalled clients (issue 37: each requests a 16 MiB file and never
reads it, holding the connection 10 s, then reconnecting) run at once while one normal client
fetches index.html in a loop. Reports the normal client's success rate and
latency median/p90 and the server's peak RSS (VmHWM) and thread count from
/proc/<pid>/status. Loopback only; clients and time are capped (--slow and
--stalled at most 500, --big at most 64, --seconds at most 120). The server
serves a temporary copy of --dir's files plus the 16 MiB big.wasm.
Standard library only.

usage: benches/serve_load.py [--bin target/release/robocal] [--dir www]
                           [--slow 60] [--big 8] [--stalled 0] [--seconds 30]
"""
import argparse, os, shutil, socket, statistics, subprocess, tempfile, threading, time

ap = argparse.ArgumentParser()
ap.add_argument("--bin", default="target/release/robocal")
ap.add_argument("--dir", default="www")
ap.add_argument("--slow", type=int, default=60)
ap.add_argument("--big", type=int, default=8)
ap.add_argument("--stalled", type=int, default=0)
ap.add_argument("--seconds", type=float, default=30)
a = ap.parse_args()
a.slow, a.stalled = min(a.slow, 500), min(a.stalled, 500)
a.big, a.seconds = min(a.big, 64), min(a.seconds, 120.0)

site = tempfile.mkdtemp(prefix="robocal-serve-load-")
for name in os.listdir(a.dir):
    if os.path.isfile(os.path.join(a.dir, name)):
        shutil.copy(os.path.join(a.dir, name), site)
with open(os.path.join(site, "big.wasm"), "wb") as f:
    f.write(b"\0" * (16 << 20))

srv = subprocess.Popen([a.bin, "serve", site, "--host", "127.0.0.1", "--port", "0"],
                       stdout=subprocess.PIPE, text=True)
line = srv.stdout.readline()
host, port = line.split(" at http://")[1].strip().rstrip("/").rsplit(":", 1)
addr = (host, int(port))
stop = time.time() + a.seconds
counts = {"slow_conns": 0, "big_sent": 0, "big_431": 0, "stalled_conns": 0}

def status(sock_data):
    try:
        return int(sock_data.split(b" ", 2)[1])
    except Exception:
        return None

def slow():
    while time.time() < stop:
        try:
            s = socket.create_connection(addr, timeout=10)
            counts["slow_conns"] += 1
            for ch in b"GET /index.html HTTP/1.1\r\nX-a: " + b"b" * 10000:
                if time.time() >= stop:
                    break
                s.send(bytes([ch]))
                time.sleep(1)
        except OSError:
            pass
        finally:
            try: s.close()
            except Exception: pass

def big():
    req = b"GET / HTTP/1.1\r\nX-Big: " + b"a" * 32768 + b"\r\n\r\n"
    while time.time() < stop:
        try:
            s = socket.create_connection(addr, timeout=10)
            s.sendall(req)
            counts["big_sent"] += 1
            if status(s.recv(4096)) == 431:
                counts["big_431"] += 1
            s.close()
        except OSError:
            time.sleep(0.05)

def stalled():
    # Requests the big file, never reads a byte of it, holds the connection
    # for 10 s (or to the end), then reconnects.
    while time.time() < stop:
        s = None
        try:
            s = socket.create_connection(addr, timeout=10)
            s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            counts["stalled_conns"] += 1
            s.sendall(b"GET /big.wasm HTTP/1.1\r\nHost: x\r\n\r\n")
            time.sleep(max(0.0, min(10.0, stop - time.time())))
        except OSError:
            time.sleep(0.05)
        finally:
            if s is not None:
                s.close()

peak = {"threads": 0}
def sample():
    while time.time() < stop:
        with open(f"/proc/{srv.pid}/status") as f:
            for l in f:
                if l.startswith("Threads:"):
                    peak["threads"] = max(peak["threads"], int(l.split()[1]))
        time.sleep(0.1)

threads = [threading.Thread(target=slow, daemon=True) for _ in range(a.slow)]
threads += [threading.Thread(target=big, daemon=True) for _ in range(a.big)]
threads += [threading.Thread(target=stalled, daemon=True) for _ in range(a.stalled)]
threads.append(threading.Thread(target=sample, daemon=True))
for t in threads:
    t.start()
time.sleep(2)  # let the slow clients occupy the workers
ok, fail, lat, codes = 0, 0, [], {}
while time.time() < stop:
    t0 = time.time()
    try:
        s = socket.create_connection(addr, timeout=30)
        s.sendall(b"GET /index.html HTTP/1.1\r\nHost: x\r\n\r\n")
        data = b""
        while chunk := s.recv(65536):
            data += chunk
        s.close()
        c = status(data)
    except OSError as e:
        c = type(e).__name__
    codes[c] = codes.get(c, 0) + 1
    if c == 200:
        ok += 1
        lat.append(time.time() - t0)
    else:
        fail += 1
    time.sleep(0.2)
with open(f"/proc/{srv.pid}/status") as f:
    st = {l.split(":")[0]: l.split(":", 1)[1].strip() for l in f}
srv.kill()
srv.wait()
shutil.rmtree(site, ignore_errors=True)
q = lambda p: sorted(lat)[int(p * (len(lat) - 1))] * 1000 if lat else float("nan")
print(f"slow clients {a.slow} (connections opened {counts['slow_conns']}), stalled clients {a.stalled} "
      f"(connections opened {counts['stalled_conns']}), oversized-head clients {a.big} "
      f"(sent {counts['big_sent']}, answered 431: {counts['big_431']}), {a.seconds:.0f} s")
print(f"normal client: {ok}/{ok + fail} ok ({100 * ok / max(1, ok + fail):.1f} %), statuses {codes}, "
      f"latency median {q(0.5):.1f} ms, p90 {q(0.9):.1f} ms")
print(f"server: VmHWM {st['VmHWM']}, threads peak {peak['threads']} (end {st['Threads']})")
