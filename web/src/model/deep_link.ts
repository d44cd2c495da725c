// The page's address is the state worth sharing: `/?space=S&clip=ID&from=F&to=T` opens that
// search (and `&hit=N` the N-th hit beside it); `/?clip=ID` opens a clip.

export interface DeepLink {
  space?: string;
  clipId?: string;
  from?: number;
  to?: number;
  hit?: number;
}

function integer(value: string | null): number | undefined {
  if (value === null || !/^\d+$/.test(value)) return undefined;
  return Number(value);
}

export function readDeepLink(search: string): DeepLink {
  const params = new URLSearchParams(search);
  const clip = params.get("clip");
  return {
    space: params.get("space") || undefined,
    clipId: clip && /^\d+$/.test(clip) ? clip : undefined,
    from: integer(params.get("from")),
    to: integer(params.get("to")),
    hit: integer(params.get("hit")),
  };
}

export function formatDeepLink(link: DeepLink): string {
  const params = new URLSearchParams();
  if (link.space) params.set("space", link.space);
  if (link.clipId) params.set("clip", link.clipId);
  if (link.from !== undefined) params.set("from", String(link.from));
  if (link.to !== undefined) params.set("to", String(link.to));
  if (link.hit !== undefined) params.set("hit", String(link.hit));
  const text = params.toString();
  return text ? `/?${text}` : "/";
}

/** Replaces the address bar's link without a reload or a history entry per change. */
export function showDeepLink(link: DeepLink): void {
  const target = formatDeepLink(link);
  if (window.location.pathname + window.location.search !== target) {
    window.history.replaceState(null, "", target);
  }
}
