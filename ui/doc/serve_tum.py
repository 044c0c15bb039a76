# A tracker for the screenshot scripts beside it: accepts one connection on tcp PORT, waits
# until something listens on udp VIDEO_PORT (the app opened its video), then sends the TUM
# lines of FILE at 30 a second. Usage: python3 ui/doc/serve_tum.py FILE PORT VIDEO_PORT
import socket, sys, time
server = socket.create_server(("127.0.0.1", int(sys.argv[2])))
conn, _ = server.accept()
video = ":%04X " % int(sys.argv[3])
while video not in open("/proc/net/udp").read():
    time.sleep(0.05)
try:
    for line in open(sys.argv[1]):
        conn.sendall(line.encode())
        time.sleep(1 / 30)
except (BrokenPipeError, ConnectionResetError):  # the app took its screenshot and quit
    pass
