/* hearth_strbuf: appends in order, pieces larger than the free space and
 * than the first capacity, the empty buffer, taking and freeing. */
#include "hearth/core.h"
#include "test_util.h"

int main(void) {
  /* an empty buffer: take gives "", free accepts it (and NULL) */
  hearth_strbuf b = {0};
  char *s = hearth_strbuf_take(&b);
  CHECK(s && s[0] == 0);
  free(s);
  hearth_strbuf_free(&b);
  hearth_strbuf_free(NULL);

  /* small pieces in order, NUL-terminated after each */
  hearth_strbuf_printf(&b, "%s=%d", "a", 1);
  CHECK(b.data && b.len == 3 && strcmp(b.data, "a=1") == 0 && !b.failed);
  hearth_strbuf_printf(&b, "%s", "");
  CHECK(b.len == 3 && b.data[3] == 0);
  hearth_strbuf_printf(&b, ",%05.1f", 2.25);
  CHECK(strcmp(b.data, "a=1,002.2") == 0 || strcmp(b.data, "a=1,002.3") == 0);
  CHECK(b.len == strlen(b.data) && b.cap > b.len);

  /* one piece far beyond the capacity, then many that grow it again */
  char big[5000];
  memset(big, 'x', sizeof big - 1);
  big[sizeof big - 1] = 0;
  hearth_strbuf_free(&b);
  hearth_strbuf_printf(&b, "<%s>", big);
  CHECK(b.len == 5001 && b.data[0] == '<' && b.data[5000] == '>' && b.data[5001] == 0);
  size_t expect = b.len;
  for (int i = 0; i < 10000; i++) {
    hearth_strbuf_printf(&b, "%d;", i % 10);
    expect += 2;
  }
  CHECK(b.len == expect && strlen(b.data) == expect && !b.failed);
  int ok = 1;
  for (int i = 0; i < 10000 && ok; i++)
    ok = b.data[5001 + 2 * i] == '0' + i % 10 && b.data[5002 + 2 * i] == ';';
  CHECK(ok);

  /* take hands over the text and leaves the buffer empty and reusable */
  s = hearth_strbuf_take(&b);
  CHECK(s && strlen(s) == expect);
  CHECK(b.data == NULL && b.len == 0 && b.cap == 0);
  free(s);
  hearth_strbuf_printf(&b, "again");
  CHECK(strcmp(b.data, "again") == 0);

  /* a failed buffer ignores appends and take gives NULL */
  b.failed = 1;
  hearth_strbuf_printf(&b, "more");
  CHECK(b.len == 5);
  CHECK(hearth_strbuf_take(&b) == NULL && b.data == NULL && !b.failed);
  TEST_MAIN_END();
}
