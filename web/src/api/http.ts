// The one place the page talks HTTP: JSON in and out, the bearer token, and errors as ApiError
// carrying the server's {code, message}. On a 401 the page asks for the token once (kept in
// sessionStorage for the tab), however many calls were refused together, and repeats them.

const TOKEN_KEY = "motiondb.token";

export class ApiError extends Error {
  constructor(
    readonly status: number,
    readonly code: number,
    message: string,
  ) {
    super(message);
    this.name = "ApiError";
  }
}

/** Asks the person for a token; resolves to null when they decline. Set by the page. */
let askToken: () => Promise<string | null> = async () => null;

export function setTokenPrompt(prompt: () => Promise<string | null>): void {
  askToken = prompt;
}

/** The prompt open now, which every call refused meanwhile waits for. */
let pendingPrompt: Promise<boolean> | null = null;

/** After a 401 to a call sent with `sent`: whether there is another token to try. */
function newToken(sent: string | null): Promise<boolean> {
  // Another call's prompt got one since this call was sent.
  if (sessionStorage.getItem(TOKEN_KEY) !== sent) return Promise.resolve(true);
  pendingPrompt ??= askToken()
    .then((token) => {
      if (token) sessionStorage.setItem(TOKEN_KEY, token.trim());
      return Boolean(token);
    })
    .finally(() => {
      pendingPrompt = null;
    });
  return pendingPrompt;
}

function headers(hasBody: boolean, token: string | null): Headers {
  const result = new Headers({ Accept: "application/json" });
  if (hasBody) result.set("Content-Type", "application/json");
  if (token) result.set("Authorization", `Bearer ${token}`);
  return result;
}

async function errorOf(response: Response): Promise<ApiError> {
  const text = await response.text();
  try {
    const body = JSON.parse(text) as { code?: number; message?: string };
    return new ApiError(response.status, body.code ?? 2, body.message ?? text);
  } catch {
    return new ApiError(response.status, 2, text || response.statusText);
  }
}

/** Sends one call; `query` values that are undefined or "" are left out. */
export async function call<T>(
  method: "GET" | "POST" | "DELETE",
  path: string,
  options: { query?: Record<string, string | number | undefined>; body?: unknown } = {},
): Promise<T> {
  const url = new URL(path, window.location.origin);
  for (const [key, value] of Object.entries(options.query ?? {})) {
    if (value !== undefined && value !== "") url.searchParams.set(key, String(value));
  }
  const body = options.body === undefined ? undefined : JSON.stringify(options.body);
  for (let attempt = 0; ; attempt++) {
    const token = sessionStorage.getItem(TOKEN_KEY);
    const response = await fetch(url, {
      method,
      headers: headers(body !== undefined, token),
      body,
    });
    if (response.ok) return (await response.json()) as T;
    if (response.status === 401 && attempt === 0 && (await newToken(token))) continue;
    throw await errorOf(response);
  }
}
