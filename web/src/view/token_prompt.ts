// Asks for the server's bearer token when a call answers 401 (the server was started with a
// token file). The page keeps it for the tab only.
import { h } from "./dom";

export function askForToken(): Promise<string | null> {
  const input = h("input", {
    type: "password",
    autocomplete: "off",
    placeholder: "token",
    "data-testid": "token",
  });
  const dialog = h(
    "dialog",
    { class: "token-dialog" },
    h(
      "form",
      { method: "dialog" },
      h("p", {}, "This server needs its access token."),
      input,
      h(
        "menu",
        {},
        h("button", { value: "cancel", class: "ghost" }, "Cancel"),
        h("button", { value: "ok", class: "primary" }, "Use token"),
      ),
    ),
  );
  document.body.appendChild(dialog);
  return new Promise((resolve) => {
    dialog.addEventListener("close", () => {
      dialog.remove();
      resolve(dialog.returnValue === "ok" && input.value.trim() ? input.value.trim() : null);
    });
    dialog.showModal();
  });
}
