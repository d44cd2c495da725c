// Entry point of the motiondb web asset browser.
import "./styles.css";
import { setTokenPrompt } from "./api/http";
import { App } from "./app";
import { byId } from "./view/dom";
import { StatusLine } from "./view/status_line";
import { askForToken } from "./view/token_prompt";

setTokenPrompt(askForToken);
new App().start().catch((error) => new StatusLine(byId("status")).error(error));
