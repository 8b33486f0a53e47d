#!/usr/bin/env python3
"""Checks of the deploy/ files: Kubernetes manifests, Dockerfile, systemd unit, nginx front.

Usage: [RDM_BINARY=build/cli/rdm] deploy_test.py [DEPLOY_DIR]   (default: ../deploy)

Checks the fields the Kubernetes API requires and the cross-references a typo would break
(selectors, probe ports, volumes, PVC names, shard counts); needs only PyYAML. With
RDM_BINARY set and Debian's nginx installed, NginxFrontTest runs deploy/nginx/nginx.conf in
front of a real `rdm serve` on loopback and holds 1,000 slow clients against it.
"""

import http.client
import json
import os
import pathlib
import re
import resource
import shlex
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import yaml

DEPLOY_DIR = pathlib.Path(__file__).resolve().parent.parent / "deploy"

API_VERSIONS = {
    "ConfigMap": "v1",
    "Deployment": "apps/v1",
    "Job": "batch/v1",
    "NetworkPolicy": "networking.k8s.io/v1",
    "PersistentVolumeClaim": "v1",
    "Secret": "v1",
    "Service": "v1",
}
ACCESS_MODES = {"ReadWriteOnce", "ReadOnlyMany", "ReadWriteMany", "ReadWriteOncePod"}
DNS_1123_LABEL = re.compile(r"^[a-z0-9]([-a-z0-9]*[a-z0-9])?$")
# `rdm` as the program of a shell command line: at the start, after a separator or exec.
RDM_IN_SHELL = re.compile(r"(^|[\s;&|(])rdm(\s|$)")


def load_documents():
    """Every non-empty YAML document under k8s/, as (file name, document)."""
    docs = []
    for path in sorted((DEPLOY_DIR / "k8s").glob("*.y*ml")):
        with open(path, encoding="utf-8") as f:
            for doc in yaml.safe_load_all(f):
                if doc is not None:
                    docs.append((path.name, doc))
    return docs


def pod_spec(doc):
    return doc["spec"]["template"]["spec"]


def containers(doc):
    spec = pod_spec(doc)
    return spec.get("initContainers", []) + spec["containers"]


def command_line(container):
    return [str(x) for x in container.get("command", []) + container.get("args", [])]


def runs_nginx(container):
    line = command_line(container)
    return bool(line) and pathlib.PurePath(line[0]).name == "nginx"


def runs_rdm(container):
    line = command_line(container)
    if line and line[0] == "rdm":
        return True
    if line[:2] in (["sh", "-c"], ["/bin/sh", "-c"], ["bash", "-c"]) and len(line) > 2:
        return bool(RDM_IN_SHELL.search(line[2]))
    return False


def parse_unit(text):
    """systemd unit text -> {section: [(key, value), ...]}."""
    sections, current = {}, None
    for raw in text.splitlines():
        line = raw.strip()
        if not line or line.startswith(("#", ";")):
            continue
        if line.startswith("[") and line.endswith("]"):
            current = sections.setdefault(line[1:-1], [])
            continue
        if current is None or "=" not in line:
            raise ValueError(f"not a unit line: {raw!r}")
        key, value = line.split("=", 1)
        current.append((key.strip(), value.strip()))
    return sections


class ManifestTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.docs = load_documents()
        cls.by_kind = {}
        for _, doc in cls.docs:
            cls.by_kind.setdefault(doc.get("kind"), []).append(doc)

    def of_kind(self, kind):
        return self.by_kind.get(kind, [])

    def pvc(self, name):
        for doc in self.of_kind("PersistentVolumeClaim"):
            if doc["metadata"]["name"] == name:
                return doc
        return None

    def test_files_exist(self):
        self.assertTrue((DEPLOY_DIR / "k8s" / "daemon.yaml").is_file())
        self.assertTrue((DEPLOY_DIR / "k8s" / "bake-job.yaml").is_file())
        self.assertGreater(len(self.docs), 0)

    def test_every_document_has_required_fields(self):
        seen = set()
        for file, doc in self.docs:
            with self.subTest(file=file, doc=doc.get("metadata", {}).get("name")):
                self.assertIsInstance(doc, dict)
                kind = doc.get("kind")
                self.assertIn(kind, API_VERSIONS, "unknown or missing kind")
                self.assertEqual(doc.get("apiVersion"), API_VERSIONS[kind])
                name = doc.get("metadata", {}).get("name")
                self.assertIsInstance(name, str)
                self.assertRegex(name, DNS_1123_LABEL)
                self.assertLessEqual(len(name), 63)
                self.assertNotIn((kind, name), seen, "duplicate object")
                seen.add((kind, name))

    def test_deployment(self):
        deployments = self.of_kind("Deployment")
        self.assertEqual(len(deployments), 1)
        for doc in deployments:
            spec = doc["spec"]
            match = spec["selector"]["matchLabels"]
            labels = spec["template"]["metadata"]["labels"]
            self.assertTrue(match)
            for key, value in match.items():
                self.assertEqual(labels.get(key), value, f"selector {key} not in template")
            self.check_containers(doc)
            # A ReadWriteOnce data volume admits one pod: one replica, no rolling overlap.
            for volume in pod_spec(doc).get("volumes", []):
                claim = volume.get("persistentVolumeClaim", {}).get("claimName")
                if claim and "ReadWriteOnce" in self.pvc(claim)["spec"]["accessModes"]:
                    self.assertEqual(spec.get("replicas", 1), 1)
                    self.assertEqual(spec["strategy"]["type"], "Recreate")
            daemon = [c for c in pod_spec(doc)["containers"] if runs_rdm(c)]
            self.assertEqual(len(daemon), 1)
            container = daemon[0]
            line = command_line(container)
            daemon_port = int(line[line.index("--port") + 1])
            for probe in ("livenessProbe", "readinessProbe"):
                get = container[probe]["httpGet"]
                self.assertEqual(get["path"], "/healthz")
                self.assertEqual(self.container_port(container, get["port"]), daemon_port)
            self.check_front(doc, daemon_port)
            token = {e["name"]: e for e in container["env"]}["RDM_TOKEN"]
            self.assertNotIn("value", token, "the token must come from a Secret")
            self.assertIn("secretKeyRef", token["valueFrom"])
            for kind in ("requests", "limits"):
                self.assertIn("memory", container["resources"][kind])

    def check_front(self, doc, daemon_port):
        """The nginx front: same image, the shipped config, listening on 8080."""
        fronts = [c for c in pod_spec(doc)["containers"] if runs_nginx(c)]
        self.assertEqual(len(fronts), 1, "one nginx front container")
        front = fronts[0]
        line = command_line(front)
        self.assertIn("daemon off;", line)
        self.assertEqual(line[line.index("-c") + 1], "/etc/rdm/nginx.conf")
        self.assertEqual(self.container_port(front, "http"), 8080)
        conf = (DEPLOY_DIR / "nginx" / "nginx.conf").read_text(encoding="utf-8")
        self.assertIn(f"server 127.0.0.1:{daemon_port}", conf)
        self.assertRegex(conf, r"\n\s*listen 8080\b")
        self.assertEqual(front["readinessProbe"]["httpGet"]["path"], "/healthz")
        for probe in ("livenessProbe", "readinessProbe"):
            action = front[probe].get("httpGet") or front[probe]["tcpSocket"]
            self.assertEqual(self.container_port(front, action["port"]), 8080)
        self.assertTrue(any(m["mountPath"] == "/tmp" for m in front["volumeMounts"]),
                        "nginx -p /tmp/ needs a writable /tmp")

    def test_network_policy_admits_the_front_only(self):
        policies = self.of_kind("NetworkPolicy")
        self.assertEqual(len(policies), 1)
        spec = policies[0]["spec"]
        pods = [d["spec"]["template"]["metadata"]["labels"] for d in self.of_kind("Deployment")]
        self.assertTrue(all(pods[0].get(k) == v
                            for k, v in spec["podSelector"]["matchLabels"].items()))
        self.assertEqual(spec["policyTypes"], ["Ingress"])
        ports = [p["port"] for rule in spec["ingress"] for p in rule["ports"]]
        self.assertEqual(ports, [8080])

    def container_port(self, container, port):
        if isinstance(port, int):
            return port
        for entry in container.get("ports", []):
            if entry.get("name") == port:
                return entry["containerPort"]
        self.fail(f"port {port!r} is not a named port of container {container['name']}")

    def test_service(self):
        services = self.of_kind("Service")
        self.assertEqual(len(services), 1)
        pods = [d["spec"]["template"] for d in self.of_kind("Deployment")]
        for doc in services:
            spec = doc["spec"]
            self.assertEqual(spec.get("type", "ClusterIP"), "ClusterIP")
            self.assertTrue(spec["ports"])
            selector = spec["selector"]
            targets = [p for p in pods
                       if all(p["metadata"]["labels"].get(k) == v for k, v in selector.items())]
            self.assertEqual(len(targets), 1, "the selector must pick the daemon's pods")
            # Clients reach the nginx front only.
            container = [c for c in targets[0]["spec"]["containers"] if runs_nginx(c)][0]
            for port in spec["ports"]:
                self.assertIsInstance(port["port"], int)
                target = port.get("targetPort", port["port"])
                self.assertEqual(self.container_port(container, target), 8080)

    def test_persistent_volume_claims(self):
        self.assertTrue(self.of_kind("PersistentVolumeClaim"))
        for doc in self.of_kind("PersistentVolumeClaim"):
            with self.subTest(pvc=doc["metadata"]["name"]):
                modes = doc["spec"]["accessModes"]
                self.assertTrue(modes)
                self.assertTrue(set(modes) <= ACCESS_MODES, modes)
                self.assertRegex(str(doc["spec"]["resources"]["requests"]["storage"]),
                                 r"^[0-9]+(Ki|Mi|Gi|Ti)?$")

    def test_jobs(self):
        jobs = self.of_kind("Job")
        self.assertEqual(len(jobs), 2)
        for doc in jobs:
            with self.subTest(job=doc["metadata"]["name"]):
                self.assertIn(pod_spec(doc)["restartPolicy"], ("Never", "OnFailure"))
                self.check_containers(doc)
                for volume in pod_spec(doc).get("volumes", []):
                    claim = volume.get("persistentVolumeClaim", {}).get("claimName")
                    if claim:  # several pods on several nodes share the output
                        self.assertIn("ReadWriteMany", self.pvc(claim)["spec"]["accessModes"])

    def test_indexed_bake_job_and_merge_agree_on_shards(self):
        indexed = [d for d in self.of_kind("Job") if d["spec"].get("completionMode") == "Indexed"]
        self.assertEqual(len(indexed), 1)
        spec = indexed[0]["spec"]
        shards = spec["completions"]
        self.assertIsInstance(shards, int)
        self.assertGreaterEqual(shards, 1)
        self.assertLessEqual(spec.get("parallelism", shards), shards)
        line = " ".join(command_line(pod_spec(indexed[0])["containers"][0]))
        self.assertIn("rdm bake", line)
        self.assertIn('--shard "${JOB_COMPLETION_INDEX}/%d"' % shards, line)
        self.assertIn("/out/shard-${JOB_COMPLETION_INDEX}", line)

        merges = [d for d in self.of_kind("Job") if d["metadata"]["name"] == "rdm-merge"]
        self.assertEqual(len(merges), 1)
        self.assertNotEqual(merges[0]["spec"].get("completionMode"), "Indexed")
        merge = command_line(pod_spec(merges[0])["containers"][0])
        self.assertEqual(merge[:2], ["rdm", "merge"])
        self.assertEqual([a for a in merge if a.startswith("/out/shard-")],
                         [f"/out/shard-{i}" for i in range(shards)])
        self.assertEqual(merge[merge.index("-o") + 1], "/out/atlas")

    def check_containers(self, doc):
        spec = pod_spec(doc)
        volumes = {v["name"] for v in spec.get("volumes", [])}
        for container in containers(doc):
            self.assertIsInstance(container.get("name"), str)
            self.assertRegex(container["name"], DNS_1123_LABEL)
            self.assertIsInstance(container.get("image"), str)
            self.assertTrue(container["image"])
            self.assertTrue(runs_rdm(container) or runs_nginx(container),
                            f"{container['name']} runs neither rdm nor its nginx front")
            for mount in container.get("volumeMounts", []):
                self.assertIn(mount["name"], volumes, "mount of an undeclared volume")
                self.assertTrue(mount["mountPath"].startswith("/"))
            for env in container.get("env", []):
                self.assertIn("name", env)
                self.assertTrue(("value" in env) != ("valueFrom" in env))
        for volume in spec.get("volumes", []):
            claim = volume.get("persistentVolumeClaim", {}).get("claimName")
            if claim:
                self.assertIsNotNone(self.pvc(claim), f"PVC {claim} is not defined")


class DockerfileTest(unittest.TestCase):
    def setUp(self):
        text = (DEPLOY_DIR / "Dockerfile").read_text(encoding="utf-8")
        # Instructions with continuation lines joined; comments dropped.
        joined = re.sub(r"\\\n", " ", text)
        self.instructions = []
        for line in joined.splitlines():
            line = line.strip()
            if line and not line.startswith("#"):
                word, _, rest = line.partition(" ")
                self.instructions.append((word.upper(), rest.strip()))

    def values(self, word):
        return [rest for w, rest in self.instructions if w == word]

    def test_starts_from_debian_bookworm(self):
        self.assertEqual(self.instructions[0][0], "FROM")
        for base in self.values("FROM"):
            self.assertRegex(base, r"^debian:bookworm(-slim)?(\s|$)")

    def test_runtime_stage(self):
        self.assertGreaterEqual(len(self.values("FROM")), 2, "multi-stage build expected")
        user = self.values("USER")[-1].split(":")[0]
        self.assertNotIn(user, ("root", "0"))
        self.assertIn("8080", self.values("EXPOSE")[-1].split())
        self.assertEqual(json.loads(self.values("ENTRYPOINT")[-1]), ["rdm"])
        cmd = json.loads(self.values("CMD")[-1])
        self.assertEqual(cmd[0], "serve")
        self.assertIn("--data-dir", cmd)
        self.assertTrue(any("/var/lib/rdm" in v for v in self.values("VOLUME")))
        self.assertTrue(any("--from=build" in v for v in self.values("COPY")))
        runtime = self.values("RUN")
        self.assertTrue(any(re.search(r"\bnginx-light\b|\bnginx\b", v) for v in runtime))
        self.assertTrue(any("deploy/nginx/nginx.conf" in v and "/etc/rdm/nginx.conf" in v
                            for v in self.values("COPY")))


class SystemdUnitTest(unittest.TestCase):
    def setUp(self):
        self.unit = parse_unit((DEPLOY_DIR / "rdm.service").read_text(encoding="utf-8"))

    def settings(self, section):
        result = {}
        for key, value in self.unit[section]:
            result.setdefault(key, []).append(value)
        return result

    def test_sections(self):
        for section in ("Unit", "Service", "Install"):
            self.assertIn(section, self.unit)
        self.assertIn("WantedBy", self.settings("Install"))

    def test_service(self):
        service = self.settings("Service")
        exec_start = shlex.split(service["ExecStart"][-1])
        self.assertTrue(exec_start[0].startswith("/"), "ExecStart needs an absolute path")
        self.assertEqual(pathlib.PurePath(exec_start[0]).name, "rdm")
        self.assertEqual(exec_start[1], "serve")
        self.assertEqual(exec_start[exec_start.index("--data-dir") + 1], "/var/lib/rdm")
        expected = {"DynamicUser": "yes", "StateDirectory": "rdm", "Restart": "on-failure",
                    "NoNewPrivileges": "yes", "ProtectSystem": "strict", "ProtectHome": "yes",
                    "PrivateTmp": "yes"}
        for key, value in expected.items():
            self.assertEqual(service.get(key, [None])[-1], value, key)
        self.assertIn("-/etc/default/rdm", service["EnvironmentFile"])
        # lavapipe JIT-compiles shaders with LLVM and needs writable executable memory.
        self.assertNotEqual(service.get("MemoryDenyWriteExecute", ["no"])[-1], "yes")


NGINX = "/usr/sbin/nginx"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get(port, path, timeout=5.0, method="GET", body=None, headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        conn.request(method, path, body, headers or {})
        reply = conn.getresponse()
        return reply.status, reply.read(), dict(reply.getheaders())
    finally:
        conn.close()


@unittest.skipUnless(os.path.exists(NGINX), "Debian's nginx is not installed at /usr/sbin/nginx")
@unittest.skipUnless(os.environ.get("RDM_BINARY"), "RDM_BINARY (the rdm executable) is not set")
class NginxFrontTest(unittest.TestCase):
    """deploy/nginx/nginx.conf in front of a real `rdm serve`, both on loopback.

    The shipped file runs with three substitutions: the listen and upstream ports become
    ephemeral ones and client_header_timeout drops from 10 s to 3 s to bound the runtime.
    """

    SLOW_CLIENTS = 1000

    @classmethod
    def setUpClass(cls):
        soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        resource.setrlimit(resource.RLIMIT_NOFILE, (min(hard, 8192), hard))
        cls.tmp = tempfile.mkdtemp(prefix="rdm_nginx_")
        cls.daemon = subprocess.Popen(
            [os.environ["RDM_BINARY"], "serve", "--data-dir", os.path.join(cls.tmp, "data"),
             "--port", "0", "--threads", "1"], stdout=subprocess.PIPE)
        line = cls.daemon.stdout.readline().decode()
        cls.daemon_port = int(line.rsplit(":", 1)[1])
        cls.port = free_port()
        conf = (DEPLOY_DIR / "nginx" / "nginx.conf").read_text(encoding="utf-8")
        for old, new in (("listen 8080", f"listen 127.0.0.1:{cls.port}"),
                         ("127.0.0.1:8081", f"127.0.0.1:{cls.daemon_port}"),
                         ("client_header_timeout 10s", "client_header_timeout 3s")):
            assert old in conf, old
            conf = conf.replace(old, new)
        path = os.path.join(cls.tmp, "nginx.conf")
        with open(path, "w", encoding="utf-8") as f:
            f.write(conf)
        args = [NGINX, "-p", cls.tmp, "-c", path, "-e", "stderr", "-g", "daemon off;"]
        check = subprocess.run(args + ["-t"], capture_output=True, text=True)
        if check.returncode != 0:
            cls.tearDownClass()
            raise AssertionError("nginx -t: " + check.stderr)
        cls.nginx = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        for _ in range(100):
            try:
                if get(cls.port, "/healthz", 1.0)[0] == 200:
                    break
            except OSError:
                time.sleep(0.05)

    @classmethod
    def tearDownClass(cls):
        for proc in (getattr(cls, "nginx", None), getattr(cls, "daemon", None)):
            if proc and proc.poll() is None:
                proc.terminate()
                proc.wait(timeout=10)
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_limits_are_answered_by_nginx(self):
        self.assertEqual(get(self.port, "/healthz")[0], 200)
        status, _, headers = get(self.port, "/healthz")
        self.assertNotIn("nginx/", headers.get("Server", ""))  # server_tokens off
        big = {f"X-H{i}": "a" * 8000 for i in range(12)}  # 96 KB of fields: over 4 x 16k
        status, body, headers = get(self.port, "/healthz", headers=big)
        self.assertEqual(status, 400)
        self.assertEqual(headers.get("Content-Type"), "application/problem+json")
        self.assertEqual(json.loads(body)["status"], 400)
        # A declared body over client_max_body_size: refused before it is sent.
        with socket.create_connection(("127.0.0.1", self.port), timeout=5) as s:
            s.sendall(b"POST /v1/scenes HTTP/1.1\r\nHost: x\r\nContent-Type: application/json"
                      b"\r\nContent-Length: 34603008\r\n\r\n")
            reply = s.recv(4096)
            self.assertTrue(reply.startswith(b"HTTP/1.1 413"), reply)
            self.assertIn(b"application/problem+json", reply)

    def test_slow_clients_do_not_stop_service(self):
        slow = []
        for _ in range(self.SLOW_CLIENTS):
            s = socket.create_connection(("127.0.0.1", self.port))
            s.sendall(b"GET /healthz HTTP/1.1\r\n")
            slow.append(s)
        # While they trickle a header byte each 0.5 s, /healthz and an upload still answer.
        worst, start, probes = 0.0, time.monotonic(), 0
        scene = json.dumps({"format": "rdm-scene", "version": 1, "size": [1, 1, 1]})
        while time.monotonic() - start < 2.5:
            for s in slow:
                try:
                    s.send(b"X")
                except OSError:
                    pass
            t = time.monotonic()
            self.assertEqual(get(self.port, "/healthz", timeout=5)[0], 200)
            status, body, _ = get(self.port, "/v1/scenes", method="POST", body=scene,
                                  headers={"Content-Type": "application/json"}, timeout=5)
            self.assertEqual(status, 201, body)
            worst = max(worst, time.monotonic() - t)
            probes += 1
            time.sleep(0.5)
        print(f"\n[ nginx ] {self.SLOW_CLIENTS} slow clients: {probes} probes, slowest "
              f"/healthz + upload {worst * 1e3:.0f} ms", file=sys.stderr)
        self.assertLess(worst, 2.0)
        # client_header_timeout (3 s here) closes them; the daemon never saw one.
        time.sleep(2.0)
        closed = 0
        for s in slow:
            s.settimeout(2.0)
            try:
                closed += s.recv(4096) == b""
            except ConnectionResetError:  # reset_timedout_connection on
                closed += 1
            except OSError:
                pass
            s.close()
        self.assertGreater(closed, self.SLOW_CLIENTS * 9 // 10)
        status, body, _ = get(self.port, "/metrics")
        self.assertEqual(status, 200)
        self.assertNotIn(b'code="408"', body)  # nginx held them, not the daemon


if __name__ == "__main__":
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        DEPLOY_DIR = pathlib.Path(sys.argv.pop(1)).resolve()
    unittest.main(verbosity=2)
