// How numbers read on the page.

export function seconds(value: number): string {
  return `${value.toFixed(2)} s`;
}

export function duration(value: number): string {
  if (value < 60) return `${value.toFixed(1)} s`;
  const minutes = Math.floor(value / 60);
  return `${minutes}:${String(Math.floor(value % 60)).padStart(2, "0")} min`;
}

export function rate(fps: number): string {
  const rounded = Math.round(fps);
  return `${Math.abs(fps - rounded) < 0.01 ? rounded : fps.toFixed(2)} fps`;
}

export function score(value: number): string {
  return value < 0.01 ? value.toExponential(2) : value.toFixed(3);
}
