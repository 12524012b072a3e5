// The check of "mercmac: Simulate", in the main session: `mercmac sim FILE --web` run by the
// extension, its page in a webview beside the editor (the extension host relaying between
// the two), a button held with the pointer, the session saved as a scenario, the panel closed
// and the process gone; then the same from the server's "simulate" lens.
import fs from "node:fs";
import path from "node:path";
import { assert, check, descendants, sleep, until } from "../lib/common.mjs";

export const SIMULATE_CHECKS = ["simulate"];

/** The `mercmac sim` processes below this code-server. */
function simProcesses(session) {
  return descendants(session.server.pid).filter((p) => /mercmac/.test(p.cmdline) && /\bsim\b/.test(p.cmdline));
}

/** The page inside the webview: VS Code puts it in an iframe (#active-frame) in an iframe. */
function webviewPage(page) {
  return page.frameLocator("iframe.webview").first().frameLocator("iframe#active-frame");
}

async function number(locator) {
  const text = (await locator.textContent({ timeout: 2000 })) || "";
  const value = Number(text.replace(/[^\d.-]/g, ""));
  if (text.trim() === "" || Number.isNaN(value)) throw new Error(`not a number: ${JSON.stringify(text)}`);
  return value;
}

export async function simulateChecks(session, options) {
  const { page } = session;

  await check("simulate", options, async (c) => {
    await session.closeEditors();
    await session.probe("await vscode.commands.executeCommand('notifications.clearAll');").catch(() => undefined);
    assert(simProcesses(session).length === 0, `a mercmac sim runs before the check: ${JSON.stringify(simProcesses(session))}`);
    await session.open("four-modes.mcm");
    await session.cursor(0, 0); // the top of the file in view: autostart and its "simulate" lens
    await session.palette("mercmac: Simulate");

    const tab = page.locator(".tabs-container .tab", { hasText: "Simulate four-modes.mcm" }).first();
    await tab.waitFor({ state: "visible", timeout: 30000 });
    const box = webviewPage(page);
    const button1 = box.getByRole("button", { name: "button 1", exact: true });
    await button1.waitFor({ state: "visible", timeout: 30000 });
    const position = box.locator('output[aria-label="position"]');
    const macro = box.locator('output[aria-label="macro"]');
    const conn = box.locator("#conn");
    await until("the page's stream to be live", async () => (await conn.textContent()) === "live", { timeout: 15000 });
    const running = simProcesses(session);
    assert(running.length === 1, `${running.length} mercmac sim processes run: ${JSON.stringify(running)}`);
    // the editor stays where it was, the webview beside it
    const groups = await session.probe("return vscode.window.tabGroups.all.map((g) => g.tabs.map((t) => t.label));");
    assert(groups.length === 2 && groups[0].includes("four-modes.mcm") && groups[1].includes("Simulate four-modes.mcm"),
      `the editor groups hold ${JSON.stringify(groups)}`);

    // four-modes.mcm picks its mode by the button held at power-on: hold 1 (latched) and
    // power-cycle, for mode 1 (jog: the stage moves while button 1 is held)
    await box.locator("#latch").check();
    await button1.click();
    await box.getByRole("button", { name: "power cycle" }).click();
    await until("macro jog", async () => /jog/.test((await macro.textContent()) || ""), { timeout: 15000 });
    await button1.click(); // lets go of the latched button
    await box.locator("#latch").uncheck();
    const still = await until("the stage to stand still", async () => {
      const a = await number(position);
      await sleep(400);
      const b = await number(position);
      return a === b ? { value: b } : false;
    }, { timeout: 15000 });

    // the check itself: button 1 held with the pointer for 1.5 s moves the stage
    session.keepMouse = true;
    const box1 = await button1.boundingBox();
    assert(box1, "button 1 has no box on the screen");
    await page.mouse.move(box1.x + box1.width / 2, box1.y + box1.height / 2);
    await page.mouse.down();
    await sleep(1000);
    const during = await number(position);
    const pressed = await button1.getAttribute("aria-pressed").catch(() => null);
    const leds = [];
    for (let n = 1; n <= 4; n++) {
      leds.push(await box.getByRole("img", { name: `LED ${n}`, exact: true }).getAttribute("data-on").catch(() => "?"));
    }
    await sleep(500);
    c.shots.push(await session.shot("28-simulate"));
    await page.mouse.up();
    session.keepMouse = false;
    const after = await number(position);
    c.note(`the panel "Simulate four-modes.mcm" beside the editor (groups ${JSON.stringify(groups)}), stream live, one mercmac sim (pid ${running[0].pid}); mode 1 by a power cycle with button 1 latched; button 1 held 1.5 s with the pointer (aria-pressed ${pressed}, LEDs ${leds.join(",")}): position ${still.value} -> ${during} (after 1 s) -> ${after}`);
    assert(during !== still.value && after !== still.value, `the position stayed at ${still.value} while button 1 was held`);

    // Save as scenario: the extension's save dialog (VS Code's own, in code-server), the file
    // beside the program, a note in the page's timeline
    const scenario = session.file("four-modes.scenario.toml");
    fs.rmSync(scenario, { force: true });
    await box.getByRole("button", { name: "save as scenario" }).click();
    const input = page.locator(".quick-input-widget input");
    await input.waitFor({ state: "visible", timeout: 10000 });
    // VS Code's simple file dialog fills its input in steps: the folder, then the name
    let offered = "";
    await until("the save dialog to offer four-modes.scenario.toml", async () => {
      offered = await input.inputValue();
      return offered.endsWith("four-modes.scenario.toml");
    }, { timeout: 10000 }).catch(() => { throw new Error(`the save dialog offers ${JSON.stringify(offered)}`); });
    await sleep(300);
    await page.keyboard.press("Enter");
    await until("the scenario file", () => fs.existsSync(scenario), { timeout: 10000 });
    const saved = fs.readFileSync(scenario, "utf8");
    assert(/^until = "\d+ms"$/m.test(saved), `the scenario file holds ${JSON.stringify(saved.slice(0, 300))}`);
    await until("the note in the timeline", async () => /Saved four-modes\.scenario\.toml \(replay with mercmac sim four-modes\.mcm --scenario four-modes\.scenario\.toml\)/
      .test(await box.locator("#log").innerText()), { timeout: 10000 });
    fs.rmSync(scenario, { force: true });
    c.note(`Save as scenario: the dialog offered ${path.basename(offered)}, ${saved.split("\n").length} lines written, the note "Saved four-modes.scenario.toml (replay with …)" in the timeline`);

    // closing the panel stops the process
    await tab.hover();
    await tab.getByRole("button", { name: /^Close/ }).click();
    await tab.waitFor({ state: "detached", timeout: 10000 });
    const begin = Date.now();
    await until("no mercmac sim process", () => simProcesses(session).length === 0, { timeout: 8000 })
      .catch(() => { throw new Error(`mercmac sim processes left after the panel closed: ${JSON.stringify(simProcesses(session))}`); });
    c.note(`the panel closed by its tab's close button: no mercmac sim process left after ${((Date.now() - begin) / 1000).toFixed(1)} s`);

    // the server's "simulate" lens on autostart runs the same command, with {uri}
    await session.focusEditor();
    const lens = page.locator(".monaco-editor .codelens-decoration a", { hasText: /simulate: the box and the stage/ }).first();
    await lens.waitFor({ state: "visible", timeout: 10000 }).catch(async () => {
      const all = await page.locator(".monaco-editor .codelens-decoration").allInnerTexts();
      throw new Error(`no "simulate" lens drawn on autostart; drawn lenses: ${JSON.stringify(all)}`);
    });
    await lens.click();
    await tab.waitFor({ state: "visible", timeout: 30000 });
    await button1.waitFor({ state: "visible", timeout: 30000 });
    await until("one mercmac sim process again", () => simProcesses(session).length === 1, { timeout: 10000 });
    await tab.getByRole("button", { name: /^Close/ }).click();
    await until("no mercmac sim process after the second panel", () => simProcesses(session).length === 0, { timeout: 8000 });
    const errors = await page.locator(".notifications-toasts .notification-list-item-message").allInnerTexts();
    assert(errors.length === 0, `notifications: ${JSON.stringify(errors)}`);
    c.note("the lens \"simulate: the box and the stage\" on autostart opened it again (button 1 shown), closed again: no process left; no notification");
    await session.closeEditors();
  });
}
