"""The motiondb HTTP/JSON API through Python's standard library (nothing to install into Blender).

Mirrors the routes of docs/api.md that the add-on needs. A failed call raises ApiError with a
message fit for Blender's report area: the server's own message for an HTTP error, what went
wrong for a server that cannot be reached.
"""
import base64
import http.client
import json
import socket
import ssl
import urllib.error
import urllib.parse
import urllib.request


class ApiError(Exception):
    """A call that failed; str() is the readable message."""


def read_token_file(path):
    """The token in a file (the CLI's --token-file): its text without surrounding whitespace."""
    try:
        with open(path, encoding="ascii") as file:
            token = file.read(1 << 20).strip()
    except (OSError, UnicodeDecodeError) as error:
        raise ApiError(f"cannot read the token file {path}: {error}") from None
    if not token or any(c.isspace() or not c.isprintable() for c in token):
        raise ApiError(f"the token file {path} holds no token (printable ASCII without spaces)")
    return token


class Client:
    """One server: its URL (http:// or https://), a bearer token or None, a CA file or None."""

    def __init__(self, url, token=None, tls_ca=None, timeout=60):
        url = url.strip().rstrip("/")
        parsed = urllib.parse.urlparse(url)
        if parsed.scheme not in ("http", "https") or not parsed.netloc:
            raise ApiError(f"the server URL {url!r} is not http://HOST:PORT or https://HOST:PORT")
        self.url = url
        self.timeout = timeout
        self._headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._context = None
        if parsed.scheme == "https":
            try:
                self._context = ssl.create_default_context(cafile=tls_ca or None)
            except (OSError, ssl.SSLError) as error:
                raise ApiError(f"cannot use the TLS CA file {tls_ca}: {error}") from None

    def call(self, method, path, body=None, query=None, raw=False):
        """The answer's JSON (or its bytes with raw=True) of METHOD path?query with a JSON body."""
        url = self.url + path
        if query:
            url += "?" + urllib.parse.urlencode(query, doseq=True)
        headers = dict(self._headers)
        data = None
        if body is not None:
            data = json.dumps(body).encode()
            headers["Content-Type"] = "application/json"
        request = urllib.request.Request(url, data=data, headers=headers, method=method)
        try:
            with urllib.request.urlopen(request, timeout=self.timeout,
                                        context=self._context) as answer:
                payload = answer.read()
        except urllib.error.HTTPError as error:
            raise ApiError(_http_error_message(error, method, path)) from None
        except urllib.error.URLError as error:
            raise ApiError(f"cannot reach the motiondb server at {self.url}: "
                           f"{_reason(error.reason)}") from None
        except (socket.timeout, TimeoutError):
            raise ApiError(f"the motiondb server at {self.url} did not answer {method} {path} "
                           f"within {self.timeout} s") from None
        except (OSError, http.client.HTTPException) as error:
            # A TLS server answers plain HTTP by dropping the connection or with a TLS alert.
            hint = " (is it an https:// server?)" if self._context is None else ""
            raise ApiError(f"the connection to {self.url} failed: {error or type(error).__name__}"
                           f"{hint}") from None
        if raw:
            return payload
        try:
            return json.loads(payload)
        except ValueError:
            raise ApiError(f"{method} {path}: the answer is not JSON: is {self.url} a motiondb "
                           "server?") from None

    # The routes, as docs/api.md lists them.
    def info(self):
        return self.call("GET", "/v1/info")

    def spaces(self):
        return self.call("GET", "/v1/spaces").get("spaces", [])

    def clip(self, clip_id):
        return self.call("GET", f"/v1/clips/{int(clip_id)}")

    def search(self, space, bvh_text, max_results, mirror=False, tags=()):
        body = {"space": space, "bvh": {"bvh": _base64(bvh_text)}, "max_results": max_results}
        if mirror:  # only when asked: a server before mirrored search refuses the field
            body["mirror"] = True
        if tags:
            body["tags"] = list(tags)
        return self.call("POST", "/v1/search", body).get("results", [])

    def export_bvh(self, clip_id, first=None, last=None):
        """The clip, or its frames first..last (at its own rate, inclusive), as BVH text."""
        query = {"format": "bvh"}
        if first is not None:
            query.update({"from": first, "to": last})
        return self.call("GET", f"/v1/clips/{int(clip_id)}/file", query=query, raw=True).decode()

    def clip_labels(self, clip_id):
        labels, token = [], ""
        while True:
            page = self.call("GET", f"/v1/clips/{int(clip_id)}/labels",
                             query={"page_token": token} if token else None)
            labels += page.get("labels", [])
            token = page.get("next_page_token", "")
            if not token:
                return labels

    def add_label(self, clip_id, start_s, end_s, descriptor, value):
        body = {"labels": [{"clip_id": str(clip_id), "start_s": start_s, "end_s": end_s,
                            "descriptor": descriptor, "value": value}]}
        return self.call("POST", "/v1/labels", body).get("labels", [])

    def find_labels(self, descriptor):
        return self.call("GET", "/v1/labels:find",
                         query={"descriptor": descriptor}).get("labels", [])

    def start_propagation(self, space, descriptors):
        return self.call("POST", "/v1/jobs", {"space": space, "descriptors": list(descriptors)})

    def job(self, job_id):
        return self.call("GET", f"/v1/jobs/{urllib.parse.quote(job_id)}")

    def ingest(self, file_name, data, tags=()):
        body = {"file_name": file_name, "bvh": _base64(data), "tags": list(tags)}
        return self.call("POST", "/v1/clips", body)


def _base64(data):
    return base64.b64encode(data.encode() if isinstance(data, str) else data).decode()


def _reason(reason):
    if isinstance(reason, ssl.SSLError):
        return f"TLS: {reason.reason or reason}"
    return getattr(reason, "strerror", None) or str(reason)


def _http_error_message(error, method, path):
    """The server's {"code", "message"} body when it sent one, else the HTTP status."""
    try:
        message = json.loads(error.read()).get("message", "")
    except (ValueError, AttributeError, OSError):
        message = ""
    if error.code == 401:
        return f"the server refused the token (401): {message or 'set the token in the add-on preferences'}"
    return f"{method} {path}: {error.code} {message or error.reason}"
